/*
 * tests/app/test_cli.c — the rayes command line (src/app/main.c, cli.c), run
 * as a child process: exit status 0 on success, 1 for bad input or a
 * failed write, 2 for usage errors; every error is exactly one line on
 * stderr naming what is wrong; a tiny render writes its PNG, EXR and
 * statistics; a failed write leaves nothing at the target; --quiet prints
 * nothing; --help (alone, or after a command: that command's usage)
 * prints on stdout with status 0; --shader-path and RAYES_SHADER_PATH
 * find the example plugin brick; an OBJ file renders (to -o, or to NAME.exr by default); convert writes a
 * built-in scene or a file as RIB; a bad scene file is one line naming
 * file:line:col, status 1, and leaves no output behind.
 *
 * Each run gets its stdout and stderr in files under
 * RAYES_TEST_TMP/app_cli (our own directory: other tests share
 * RAYES_TEST_TMP and may run at the same time), runs in that directory so
 * a default output name cannot land elsewhere, and sees RAYES_DATA only
 * when a case sets it.
 */
#include <dirent.h>
#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "image/image.h"
#include "test.h"

#ifndef RAYES_BIN
#error "RAYES_BIN must name the rayes program"
#endif
#ifndef RAYES_TEST_TMP
#error "RAYES_TEST_TMP must name a scratch directory"
#endif
#ifndef RAYES_TEST_DATA
#error "RAYES_TEST_DATA must name the shared data directory"
#endif

#define SCRATCH_DIR RAYES_TEST_TMP "/app_cli"
#define OUT_FILE SCRATCH_DIR "/stdout.txt"
#define ERR_FILE SCRATCH_DIR "/stderr.txt"

extern char **environ;

/* What one run left behind. */
typedef struct Run {
    int status;     /* exit status, or -1 if the child did not exit normally */
    char out[16384]; /* stdout, NUL-terminated (truncated) */
    char err[8192]; /* stderr, NUL-terminated (truncated) */
} Run;

/* ------------------------------------------------------------- helpers */

static void read_file(const char *path, char *buf, size_t size)
{
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(buf, 1, size - 1, f) : 0;
    buf[n] = '\0';
    if (f)
        fclose(f);
}

/* Runs RAYES_BIN with argv (NULL-terminated, without the program name) in
 * SCRATCH_DIR, RAYES_DATA removed from the environment and set to data if
 * data is not NULL. */
static void run_bin(Run *r, const char *bin, const char *data, const char *const *argv)
{
    const char *args[32] = {bin};
    int n = 1;
    for (; argv[n - 1] && n < 31; n++)
        args[n] = argv[n - 1];
    args[n] = NULL;

    char data_var[4200];
    snprintf(data_var, sizeof data_var, "RAYES_DATA=%s", data ? data : "");
    const char *env[512];
    int m = 0;
    for (char **e = environ; *e && m < 510; e++)
        if (strncmp(*e, "RAYES_DATA=", 11) != 0)
            env[m++] = *e;
    if (data)
        env[m++] = data_var;
    env[m] = NULL;

    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        FILE *o = freopen(OUT_FILE, "w", stdout);
        FILE *e = freopen(ERR_FILE, "w", stderr);
        if (!o || !e || chdir(SCRATCH_DIR) != 0)
            _exit(127);
        execve(bin, (char *const *)args, (char *const *)env);
        _exit(127);
    }
    int ws = 0;
    r->status = -1;
    if (pid > 0 && waitpid(pid, &ws, 0) == pid && WIFEXITED(ws))
        r->status = WEXITSTATUS(ws);
    read_file(OUT_FILE, r->out, sizeof r->out);
    read_file(ERR_FILE, r->err, sizeof r->err);
}

static void run(Run *r, const char *data, const char *const *argv)
{
    run_bin(r, RAYES_BIN, data, argv);
}

static int count_char(const char *s, char c)
{
    int n = 0;
    for (; *s; s++)
        n += *s == c;
    return n;
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void copy_file(const char *from, const char *to)
{
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    char buf[65536];
    size_t n;
    while (a && b && (n = fread(buf, 1, sizeof buf, a)) > 0)
        CHECK(fwrite(buf, 1, n, b) == n);
    CHECK(a && b);
    if (a)
        fclose(a);
    if (b)
        fclose(b);
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

/* Runs and checks a failure: the status, one line on stderr containing
 * each of the NULL-terminated `names`, nothing on stdout. */
static void expect_error(int status, const char *data, const char *const *argv,
                         const char *const *names)
{
    static Run r;
    run(&r, data, argv);
    CHECK(r.status == status);
    CHECK(count_char(r.err, '\n') == 1);
    CHECK(r.err[0] != '\0' && r.err[strlen(r.err) - 1] == '\n');
    CHECK(r.out[0] == '\0');
    int named = 1;
    for (int i = 0; names[i]; i++)
        named &= strstr(r.err, names[i]) != NULL;
    CHECK(named);
    if (r.status != status || count_char(r.err, '\n') != 1 || !named)
        fprintf(stderr, "  rayes %s ...: status %d, stderr:\n%s", argv[0] ? argv[0] : "",
                r.status, r.err);
}

#define ARGS(...) ((const char *const[]){__VA_ARGS__, NULL})

static void setup(void)
{
    mkdir(RAYES_TEST_TMP, 0777);
    mkdir(SCRATCH_DIR, 0777); /* EEXIST is fine */
}

/* --------------------------------------------------------------- tests */

static void test_version_and_help(void)
{
    static Run r;
    setup();
    run(&r, NULL, ARGS("--version"));
    CHECK(r.status == 0);
    CHECK(strncmp(r.out, "rayes ", 6) == 0);
    CHECK(strchr("0123456789", r.out[6]) != NULL && strchr(r.out, '.') != NULL);
    CHECK(count_char(r.out, '\n') == 1);
    CHECK(r.err[0] == '\0');

    run(&r, NULL, ARGS("--help"));
    CHECK(r.status == 0);
    CHECK(strstr(r.out, "usage:") != NULL && strstr(r.out, "--spp") != NULL);
    CHECK(r.err[0] == '\0');

    /* Each command's own usage, on stdout, status 0, wherever --help is. */
    run(&r, NULL, ARGS("render", "--help"));
    CHECK(r.status == 0);
    CHECK(strncmp(r.out, "usage: rayes render", 19) == 0 && strstr(r.out, "--spp") != NULL);
    CHECK(strstr(r.out, "--screenshot") == NULL && r.err[0] == '\0');
    run(&r, NULL, ARGS("render", "cornell", "--spp", "2", "-h"));
    CHECK(r.status == 0 && strncmp(r.out, "usage: rayes render", 19) == 0);
    run(&r, NULL, ARGS("view", "--help"));
    CHECK(r.status == 0);
    CHECK(strncmp(r.out, "usage: rayes view", 17) == 0 && strstr(r.out, "--screenshot") != NULL);
    CHECK(strstr(r.out, "--spp") != NULL && r.err[0] == '\0');
    run(&r, NULL, ARGS("convert", "--help"));
    CHECK(r.status == 0);
    CHECK(strncmp(r.out, "usage: rayes convert", 20) == 0 && strstr(r.out, "--spp") == NULL);
    CHECK(r.err[0] == '\0');
}

/* No arguments: the usage goes to stderr (several lines; it is the answer,
 * not an error message) and the status is 2. */
static void test_no_arguments(void)
{
    static Run r;
    const char *const none[] = {NULL};
    setup();
    run(&r, NULL, none);
    CHECK(r.status == 2);
    CHECK(strstr(r.err, "usage:") != NULL);
    CHECK(r.out[0] == '\0');
}

static void test_usage_errors(void)
{
    setup();
    expect_error(2, NULL, ARGS("frobnicate"), ARGS("frobnicate"));
    expect_error(2, NULL, ARGS("render", "--spp", "x"), ARGS("--spp", "\"x\""));
    expect_error(2, NULL, ARGS("render", "--spp", "0"), ARGS("--spp"));
    expect_error(2, NULL, ARGS("render", "--spp"), ARGS("--spp"));
    expect_error(2, NULL, ARGS("render", "--res", "0"), ARGS("--res"));
    expect_error(2, NULL, ARGS("render", "--res", "16x"), ARGS("--res"));
    expect_error(2, NULL, ARGS("render", "--quality", "best"), ARGS("--quality", "best"));
    expect_error(2, NULL, ARGS("render", "--bogus", "1"), ARGS("--bogus"));
    expect_error(2, NULL, ARGS("render", "--gridsize", "0"), ARGS("--gridsize", "1 to 4096"));
    expect_error(2, NULL, ARGS("render", "--gridsize", "5000"), ARGS("--gridsize"));
    expect_error(2, NULL, ARGS("render", "--dice-offscreen", "0.5"), ARGS("--dice-offscreen"));
    expect_error(2, NULL, ARGS("render", "--vertex-budget", "-1"), ARGS("--vertex-budget"));
    expect_error(2, NULL, ARGS("render", "--gi", "photons"), ARGS("--gi", "photons"));
    expect_error(2, NULL, ARGS("render", "--pbgi-raster", "7"), ARGS("--pbgi-raster", "even"));
    expect_error(2, NULL, ARGS("render", "--pbgi-solid-angle", "0"), ARGS("--pbgi-solid-angle"));
    expect_error(2, NULL, ARGS("render", "-o", "out.txt"), ARGS("out.txt", ".png"));
    expect_error(2, NULL, ARGS("render", "cornell", "cornell-teapots"), ARGS("one scene"));
    expect_error(2, NULL, ARGS("render", "nosuchscene", "--res", "16"), ARGS("nosuchscene"));
    CHECK(!exists(SCRATCH_DIR "/nosuchscene.exr"));
}

/* Without --data or RAYES_DATA, the program finds ../shared/data beside
 * the checkout that built it (where RAYES_TEST_DATA is); a copy elsewhere
 * finds none and says where to point. */
static void test_missing_data(void)
{
    static Run r;
    setup();
    /* a build directory nested deeper than CHECKOUT/build finds none */
    char beside[4200];
    snprintf(beside, sizeof beside, "%s", RAYES_BIN);
    *strrchr(beside, '/') = '\0';
    strcat(beside, "/../../shared/data/teapot.bpt");
    if (access(beside, R_OK) == 0) {
        remove(SCRATCH_DIR "/cornell-teapots.exr");
        run(&r, NULL, ARGS("render", "cornell-teapots", "--res", "8", "--spp", "1", "--quiet"));
        CHECK(r.status == 0 && r.err[0] == '\0');
        CHECK(file_size(SCRATCH_DIR "/cornell-teapots.exr") > 8);
        remove(SCRATCH_DIR "/cornell-teapots.exr");
    }
    mkdir(SCRATCH_DIR "/bin", 0777);
    copy_file(RAYES_BIN, SCRATCH_DIR "/bin/rayes");
    chmod(SCRATCH_DIR "/bin/rayes", 0755);
    run_bin(&r, SCRATCH_DIR "/bin/rayes", NULL,
            ARGS("render", "cornell-teapots", "--res", "16", "--quiet"));
    CHECK(r.status == 1 && count_char(r.err, '\n') == 1);
    CHECK(strstr(r.err, "teapot.bpt") && strstr(r.err, "--data"));
    remove(SCRATCH_DIR "/bin/rayes");
    expect_error(1, NULL,
                 ARGS("render", "cornell-teapots", "--res", "16", "--data",
                      SCRATCH_DIR "/no-such-dir"),
                 ARGS(SCRATCH_DIR "/no-such-dir/teapot.bpt"));
    expect_error(1, SCRATCH_DIR "/no-such-env-dir",
                 ARGS("render", "cornell-teapots", "--res", "16"),
                 ARGS(SCRATCH_DIR "/no-such-env-dir/teapot.bpt"));
    CHECK(!exists(SCRATCH_DIR "/cornell-teapots.exr"));
}

static void test_render_outputs(void)
{
    static Run r;
    setup();
    remove(SCRATCH_DIR "/a.png");
    remove(SCRATCH_DIR "/a.exr");
    remove(SCRATCH_DIR "/s.json");
    run(&r, NULL,
        ARGS("render", "cornell", "--res", "16", "--spp", "1", "--threads", "2", "-o",
             SCRATCH_DIR "/a.png", "-o", SCRATCH_DIR "/a.exr", "--stats", SCRATCH_DIR "/s.json",
             "--quiet"));
    CHECK(r.status == 0);
    CHECK(r.out[0] == '\0');
    CHECK(r.err[0] == '\0');
    if (r.status != 0)
        fprintf(stderr, "  stderr: %s", r.err);
    CHECK(file_size(SCRATCH_DIR "/a.png") > 8);
    CHECK(file_size(SCRATCH_DIR "/a.exr") > 8);
    CHECK(file_size(SCRATCH_DIR "/s.json") > 2);
    char json[8192];
    read_file(SCRATCH_DIR "/s.json", json, sizeof json);
    CHECK(json[0] == '{' && strstr(json, "\"scene\": \"cornell\"") != NULL);
}

/* Without --quiet the summary goes to stdout and names each output. */
static void test_render_summary(void)
{
    static Run r;
    setup();
    run(&r, RAYES_TEST_DATA,
        ARGS("render", "--res", "8x4", "--spp", "1", "--threads", "1", "-o",
             SCRATCH_DIR "/b.png"));
    CHECK(r.status == 0);
    CHECK(strstr(r.out, "cornell, 8x4, 1 spp") != NULL);
    CHECK(strstr(r.out, SCRATCH_DIR "/b.png") != NULL);
    CHECK(file_size(SCRATCH_DIR "/b.png") > 8);
}

/* RAYES_DATA alone finds the teapot patches. */
static void test_data_from_environment(void)
{
    static Run r;
    setup();
    remove(SCRATCH_DIR "/t.png");
    run(&r, RAYES_TEST_DATA,
        ARGS("render", "cornell-teapots", "--res", "8", "--spp", "1", "--threads", "1",
             "--quiet", "-o", SCRATCH_DIR "/t.png"));
    CHECK(r.status == 0);
    CHECK(r.err[0] == '\0' && r.out[0] == '\0');
    CHECK(file_size(SCRATCH_DIR "/t.png") > 8);
}

static void test_unwritable_output(void)
{
    setup();
    expect_error(1, NULL,
                 ARGS("render", "--res", "8", "--spp", "1", "--quiet", "-o",
                      SCRATCH_DIR "/missing-dir/x.png"),
                 ARGS(SCRATCH_DIR "/missing-dir/x.png"));
    CHECK(!exists(SCRATCH_DIR "/missing-dir/x.png"));
    CHECK(!exists(SCRATCH_DIR "/missing-dir"));
    expect_error(1, NULL,
                 ARGS("render", "--res", "8", "--spp", "1", "--quiet", "-o",
                      SCRATCH_DIR "/c.png", "--stats", SCRATCH_DIR "/missing-dir/s.json"),
                 ARGS(SCRATCH_DIR "/missing-dir/s.json"));
    CHECK(!exists(SCRATCH_DIR "/missing-dir"));
}

/* cornell-brick needs the plugin brick.so: missing, it is a one-line error
 * (status 1) naming the shader and --shader-path; with --shader-path (or
 * RAYES_SHADER_PATH) the render succeeds. */
/* Nonzero if the two files hold the same bytes (and at most 64 KB). */
static int same_file(const char *pa, const char *pb)
{
    static char a[1 << 16], b[1 << 16];
    long na = file_size(pa), nb = file_size(pb);
    if (!(na > 0 && na == nb && na < (long)sizeof a))
        return 0;
    FILE *fa = fopen(pa, "rb"), *fb = fopen(pb, "rb");
    int same = fa && fb && fread(a, 1, (size_t)na, fa) == (size_t)na &&
               fread(b, 1, (size_t)nb, fb) == (size_t)nb && memcmp(a, b, (size_t)na) == 0;
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

static void test_shader_path(void)
{
    static Run r;
    setup();
    unsetenv("RAYES_SHADER_PATH");
    remove(SCRATCH_DIR "/brick.png");
    expect_error(1, NULL, ARGS("render", "cornell-brick", "--res", "8", "--spp", "1", "--quiet"),
                 ARGS("unknown shader \"brick\"", "--shader-path"));
    expect_error(1, NULL,
                 ARGS("render", "cornell-brick", "--res", "8", "--quiet", "--shader-path",
                      SCRATCH_DIR "/no-such-dir"),
                 ARGS(SCRATCH_DIR "/no-such-dir"));
    expect_error(2, NULL, ARGS("render", "--shader-path"), ARGS("--shader-path"));
    CHECK(!exists(SCRATCH_DIR "/cornell-brick.exr"));
    run(&r, NULL,
        ARGS("render", "cornell-brick", "--res", "16", "--spp", "1", "--quiet", "--shader-path",
             "/nonexistent:" RAYES_TEST_SHADERS, "-o", SCRATCH_DIR "/brick.png"));
    CHECK(r.status == 0 && r.err[0] == '\0');
    if (r.status != 0)
        fprintf(stderr, "  stderr: %s", r.err);
    CHECK(file_size(SCRATCH_DIR "/brick.png") > 8);
    remove(SCRATCH_DIR "/brick.png");
    setenv("RAYES_SHADER_PATH", RAYES_TEST_SHADERS, 1);
    run(&r, NULL,
        ARGS("render", "cornell-brick", "--res", "16", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/brick.png"));
    unsetenv("RAYES_SHADER_PATH");
    CHECK(r.status == 0 && file_size(SCRATCH_DIR "/brick.png") > 8);
    /* a RIB file names the plugin: converted (no plugin needed to write
     * it), it renders the built-in scene's bytes when the plugin is found,
     * and matte with a warning when it is not */
    run(&r, NULL, ARGS("convert", "cornell-brick", SCRATCH_DIR "/brick.rib", "--quiet"));
    CHECK(r.status == 0);
    run(&r, NULL,
        ARGS("render", "cornell-brick", "--res", "16", "--spp", "1", "--quiet", "--shader-path",
             RAYES_TEST_SHADERS, "-o", SCRATCH_DIR "/brick-builtin.exr"));
    CHECK(r.status == 0);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/brick.rib", "--res", "16", "--spp", "1", "--quiet",
             "--shader-path", RAYES_TEST_SHADERS, "-o", SCRATCH_DIR "/brick-rib.exr"));
    CHECK(r.status == 0 && r.err[0] == '\0');
    CHECK(same_file(SCRATCH_DIR "/brick-builtin.exr", SCRATCH_DIR "/brick-rib.exr"));
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/brick.rib", "--res", "16", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/brick-rib.exr"));
    CHECK(r.status == 0 && strstr(r.err, "\"brick\" is neither built in nor a plugin") != NULL);
}

/* Nonzero if SCRATCH_DIR holds a file whose name contains part. */
static int scratch_has(const char *part)
{
    DIR *d = opendir(SCRATCH_DIR);
    int found = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        found |= strstr(e->d_name, part) != NULL;
    if (d)
        closedir(d);
    return found;
}

#define OBJ_SCENE                                                                          \
    "# a floor and a wall\n"                                                               \
    "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -1 1 -1\nv 1 1 -1\n"                      \
    "f 4 3 2 1\nf 1 2 6 5\n"

static void test_render_obj(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/room.obj", OBJ_SCENE);
    remove(SCRATCH_DIR "/room.png");
    remove(SCRATCH_DIR "/room.exr");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/room.obj", "--res", "16", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/room.png"));
    CHECK(r.status == 0 && r.err[0] == '\0' && r.out[0] == '\0');
    if (r.status != 0)
        fprintf(stderr, "  stderr: %s", r.err);
    CHECK(file_size(SCRATCH_DIR "/room.png") > 8);
    /* no -o: NAME.exr in the working directory */
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/room.obj", "--res", "8", "--spp", "1", "--quiet"));
    CHECK(r.status == 0);
    CHECK(file_size(SCRATCH_DIR "/room.exr") > 8);
}

/* RIB's Option "limits" "gridsize" (and "texturememory") reach the render
 * unless --gridsize says otherwise; the statistics say which was used. */
static void test_rib_grid_size(void)
{
    static Run r;
    char json[8192];
    setup();
    test_write_text(SCRATCH_DIR "/grid.rib", "Option \"limits\" \"gridsize\" [32]\n"
                                             "Option \"limits\" \"texturememory\" [2048]\n"
                                             "Projection \"perspective\" \"fov\" 40\n"
                                             "WorldBegin\nLightSource \"pointlight\" 1\n"
                                             "Translate 0 0 5\nSphere 1 -1 1 360\n"
                                             "WorldEnd\n");
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/grid.rib", "--res", "16", "--spp", "1", "--quiet",
                       "-o", SCRATCH_DIR "/grid.png", "--stats", SCRATCH_DIR "/grid.json"));
    CHECK(r.status == 0 && r.err[0] == '\0');
    read_file(SCRATCH_DIR "/grid.json", json, sizeof json);
    CHECK(strstr(json, "\"grid_size\": 32,") != NULL);
    CHECK(strstr(json, "\"budget_bytes\": 2097152") != NULL); /* texturememory, KB */
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/grid.rib", "--res", "16", "--spp", "1", "--quiet",
                       "--gridsize", "128", "-o", SCRATCH_DIR "/grid.png", "--stats",
                       SCRATCH_DIR "/grid.json"));
    CHECK(r.status == 0);
    read_file(SCRATCH_DIR "/grid.json", json, sizeof json);
    CHECK(strstr(json, "\"grid_size\": 128,") != NULL);
}

/* --spp on the command line takes the samples asked for everywhere: a
 * file's adaptive sampling (Hider "maxsamples") is off unless --max-spp
 * asks for it too. */
static void test_spp_over_file_sampling(void)
{
    static Run r;
    char json[8192];
    setup();
    test_write_text(SCRATCH_DIR "/adapt.rib", "Hider \"raytrace\" \"int minsamples\" [4] "
                                              "\"int maxsamples\" [512]\nPixelVariance 0.0001\n"
                                              "Projection \"perspective\" \"fov\" 40\n"
                                              "WorldBegin\nLightSource \"pointlight\" 1\n"
                                              "Translate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/adapt.rib", "--res", "16x16", "--spp", "2", "--quiet", "-o",
             SCRATCH_DIR "/adapt.png", "--stats", SCRATCH_DIR "/adapt.json"));
    CHECK(r.status == 0);
    read_file(SCRATCH_DIR "/adapt.json", json, sizeof json);
    CHECK(strstr(json, "\"camera\": 512,") != NULL); /* 16 x 16 x 2 */
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/adapt.rib", "--res", "16", "--quiet", "-o",
             SCRATCH_DIR "/adapt.png", "--stats", SCRATCH_DIR "/adapt.json"));
    CHECK(r.status == 0);
    read_file(SCRATCH_DIR "/adapt.json", json, sizeof json);
    const char *c = strstr(json, "\"camera\": ");
    long camera = c ? strtol(c + 10, NULL, 10) : 0;
    CHECK(camera > 1024); /* the file's: 4 a pixel, more at the sphere's edge */
}

/* --res W alone keeps the scene file's aspect ratio (a 1280 x 720 pbrt
 * file surveyed at --res 200 came out 200 x 200, framed unlike its
 * reference); W x H is taken as given, and a scene without a size is
 * square. */
static void test_res_width_keeps_aspect(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/wide.rib",
                    "Format 64 36 1\nProjection \"perspective\" \"fov\" 40\n"
                    "WorldBegin\nLightSource \"pointlight\" 1\n"
                    "Translate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n");
    const struct {
        const char *res;
        int w, h;
    } cases[3] = {{"32", 32, 18}, {"20x20", 20, 20}, {"7", 7, 4}};
    for (int k = 0; k < 3; k++) {
        run(&r, NULL,
            ARGS("render", SCRATCH_DIR "/wide.rib", "--res", cases[k].res, "--spp", "1", "--quiet",
                 "-o", SCRATCH_DIR "/wide.exr"));
        CHECK(r.status == 0);
        int w = 0, h = 0;
        float *px = NULL;
        char err[256];
        CHECK(image_read_exr(SCRATCH_DIR "/wide.exr", &w, &h, &px, err, sizeof err) == RAYES_OK);
        CHECK(w == cases[k].w && h == cases[k].h);
        free(px);
    }
    run(&r, NULL,
        ARGS("render", "cornell", "--res", "12", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/sq.exr"));
    int w = 0, h = 0;
    float *px = NULL;
    char err[256];
    CHECK(r.status == 0 &&
          image_read_exr(SCRATCH_DIR "/sq.exr", &w, &h, &px, err, sizeof err) == RAYES_OK);
    CHECK(w == 12 && h == 12);
    free(px);
}

/* --png-curve: a classic RIB file's PNG is RenderMan's (linear) unless
 * the command line asks for sRGB, which lifts a mid grey. */
static void test_png_curve(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/grey.rib", "Projection \"perspective\" \"fov\" 10\n"
                                             "WorldBegin\nLightSource \"ambientlight\" 1 "
                                             "\"intensity\" 0.25\nSurface \"matte\"\n"
                                             "Translate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n");
    float *px[2] = {NULL, NULL};
    const char *curve[2] = {"linear", "srgb"};
    for (int k = 0; k < 2; k++) {
        char out[256], err[256];
        snprintf(out, sizeof out, SCRATCH_DIR "/grey-%s.png", curve[k]);
        run(&r, NULL,
            k == 0 ? ARGS("render", SCRATCH_DIR "/grey.rib", "--res", "8", "--spp", "1", "--quiet",
                          "--bounces", "0", "-o", out)
                   : ARGS("render", SCRATCH_DIR "/grey.rib", "--res", "8", "--spp", "1", "--quiet",
                          "--bounces", "0", "--png-curve", "srgb", "-o", out));
        CHECK(r.status == 0);
        int w, h;
        CHECK(image_read_png(out, &w, &h, &px[k], err, sizeof err) == RAYES_OK);
    }
    /* read back as sRGB: the linear file's 64 is 0.0513, the sRGB one's 0.25 */
    CHECK(px[0] && fabsf(px[0][4 * (4 * 8 + 4)] - 0.0513f) < 0.002f);
    CHECK(px[1] && fabsf(px[1][4 * (4 * 8 + 4)] - 0.25f) < 0.003f);
    free(px[0]);
    free(px[1]);
    expect_error(2, NULL, ARGS("render", "--png-curve", "log"),
                 (const char *const[]){"--png-curve", NULL});
}

/* RIB's Option "limits" "opacitycachememory" (KB) sets the opacity
 * entries' budget unless --opacity-cache-mb says otherwise. */
static void test_rib_opacity_cache_memory(void)
{
    static Run r;
    char json[8192];
    setup();
    test_write_text(SCRATCH_DIR "/ocm.rib", "Option \"limits\" \"opacitycachememory\" [2048]\n"
                                            "Projection \"perspective\" \"fov\" 40\n"
                                            "WorldBegin\nLightSource \"pointlight\" 1\n"
                                            "Translate 0 0 5\nSphere 1 -1 1 360\n"
                                            "WorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/ocm.rib", "--res", "8", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/ocm.png", "--stats", SCRATCH_DIR "/ocm.json"));
    CHECK(r.status == 0 && r.err[0] == '\0');
    read_file(SCRATCH_DIR "/ocm.json", json, sizeof json);
    const char *o = strstr(json, "\"opacity\": {");
    CHECK(o && strstr(o, "\"budget_bytes\": 2097152,") != NULL);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/ocm.rib", "--res", "8", "--spp", "1", "--quiet",
             "--opacity-cache-mb", "5", "-o", SCRATCH_DIR "/ocm.png", "--stats",
             SCRATCH_DIR "/ocm.json"));
    CHECK(r.status == 0);
    read_file(SCRATCH_DIR "/ocm.json", json, sizeof json);
    o = strstr(json, "\"opacity\": {");
    CHECK(o && strstr(o, "\"budget_bytes\": 5000000,") != NULL);
}

/* --vertex-budget: a scene needing more grid vertices is diced coarser,
 * with one warning giving the need and the factor, and the statistics
 * report the factor; --dice-offscreen is read. */
static void test_vertex_budget(void)
{
    static Run r;
    char json[8192];
    setup();
    test_write_text(SCRATCH_DIR "/budget.rib", "Projection \"perspective\" \"fov\" 40\n"
                                               "WorldBegin\nLightSource \"pointlight\" 1\n"
                                               "Translate 0 0 5\nSphere 1 -1 1 360\n"
                                               "WorldEnd\n");
    /* 64 x 48 (RIB's 4:3): the sphere's grid sizes come in steps, and a
     * round of coarsening that saved nothing once stopped at 1156 */
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/budget.rib", "--res", "64", "--spp", "1", "--quiet",
             "--vertex-budget", "0.001", "--dice-offscreen", "2", "-o", SCRATCH_DIR "/budget.png",
             "--stats", SCRATCH_DIR "/budget.json"));
    CHECK(r.status == 0);
    CHECK(strstr(r.err, "more than the budget of 1000 (--vertex-budget)") != NULL);
    CHECK(count_char(r.err, '\n') == 1);
    read_file(SCRATCH_DIR "/budget.json", json, sizeof json);
    const char *v = strstr(json, "\"grid_vertices\": ");
    CHECK(v && atol(v + strlen("\"grid_vertices\": ")) <= 1000);
    CHECK(strstr(json, "\"coarsened\": 1,") == NULL && strstr(json, "\"coarsened\"") != NULL);
}

/* Displacement "null" (RenderMan's "no shader", which the RIB writer
 * writes to end a displacement) is read silently. */
static void test_null_displacement(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/null.rib", "Projection \"perspective\" \"fov\" 40\n"
                                             "WorldBegin\nLightSource \"pointlight\" 1\n"
                                             "Displacement \"bumpy\"\nDisplacement \"null\"\n"
                                             "Translate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/null.rib", "--res", "16", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/null.png"));
    CHECK(r.status == 0 && r.err[0] == '\0');
}

/* Renders RIB text at 16 x 16, 1 sample, into r; it must succeed. */
static void render_rib_text(Run *r, const char *text)
{
    test_write_text(SCRATCH_DIR "/text.rib", text);
    run(r, NULL,
        ARGS("render", SCRATCH_DIR "/text.rib", "--res", "16", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/text.png"));
    CHECK(r->status == 0);
}

/* BMRT's Attribute "light" "shadows": "on" and "off" are read silently
 * (the lights that follow cast shadows or not), anything else warns. */
static void test_light_shadows_attribute(void)
{
    static Run r;
    setup();
    static const char *const values[3] = {"on", "off", "maybe"};
    for (int k = 0; k < 3; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "Projection \"perspective\" \"fov\" 40\nWorldBegin\n"
                 "Attribute \"light\" \"string shadows\" [\"%s\"]\n"
                 "LightSource \"pointlight\" 1 \"from\" [0 0 0]\nTranslate 0 0 5\n"
                 "Surface \"matte\"\nSphere 1 -1 1 360\nWorldEnd\n",
                 values[k]);
        render_rib_text(&r, text);
        /* "off" turns the lights' shadows off (tests/io/test_rib_uberlight.c) */
        CHECK(k == 2 ? strstr(r.err, "expected \"on\" or \"off\"") != NULL : r.err[0] == '\0');
    }
}

/* Requests that say what rayes does draw no warning (ShadingInterpolation
 * "smooth", Illuminate turning an area light on); their other forms say
 * what is not done, once. */
static void test_quiet_requests(void)
{
    static Run r;
    setup();
    static const char *const requests[4] = {"ShadingInterpolation \"smooth\"", "Illuminate 2 1",
                                            "ShadingInterpolation \"constant\"", "Illuminate 2 0"};
    for (int k = 0; k < 4; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "Projection \"perspective\" \"fov\" 40\nWorldBegin\n"
                 "LightSource \"pointlight\" 1 \"from\" [0 0 0]\n"
                 "AttributeBegin\nAreaLightSource \"arealight\" 2\nTranslate 0 2 5\n"
                 "Disk 0 0.5 360\nAttributeEnd\n%s\nTranslate 0 0 5\n"
                 "Surface \"matte\"\nSphere 1 -1 1 360\nWorldEnd\n",
                 requests[k]);
        render_rib_text(&r, text);
        CHECK(k < 2 ? r.err[0] == '\0' : count_char(r.err, '\n') == 1);
        if (k == 2)
            CHECK(strstr(r.err, "ShadingInterpolation") != NULL);
        if (k == 3)
            CHECK(strstr(r.err, "Illuminate of the area light 2") != NULL);
    }
}

/* A scene without lights: one warning naming the scene and the way out,
 * and a black image of a matte sphere; --default-light adds a headlight
 * that lights it. Without a Surface, RenderMan's defaultsurface draws it
 * (it needs no light). */
static void test_default_light(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/dark.rib", "Projection \"perspective\" \"fov\" 40\n"
                                             "WorldBegin\nTranslate 0 0 5\nSurface \"matte\"\n"
                                             "Sphere 1 -1 1 360\nWorldEnd\n");
    test_write_text(SCRATCH_DIR "/nosurface.rib", "Projection \"perspective\" \"fov\" 40\n"
                                                  "WorldBegin\nTranslate 0 0 5\nSphere 1 -1 1 360\n"
                                                  "WorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/nosurface.rib", "--res", "16", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/nosurface.exr"));
    CHECK(r.status == 0 && strstr(r.err, "the scene has no lights"));
    {
        int w = 0, h = 0;
        float *px = NULL;
        char err[256];
        CHECK(image_read_exr(SCRATCH_DIR "/nosurface.exr", &w, &h, &px, err, sizeof err) ==
              RAYES_OK);
        CHECK(px && px[4 * (8 * w + 8)] > 0.5f); /* the sphere's middle: Ka + Kd */
        free(px);
    }
    float mean[2] = {-1, -1};
    for (int lit = 0; lit < 2; lit++) {
        const char *out = lit ? SCRATCH_DIR "/lit.exr" : SCRATCH_DIR "/dark.exr";
        if (lit)
            run(&r, NULL, ARGS("render", SCRATCH_DIR "/dark.rib", "--res", "16", "--spp", "1",
                               "--quiet", "--default-light", "-o", out));
        else
            run(&r, NULL, ARGS("render", SCRATCH_DIR "/dark.rib", "--res", "16", "--spp", "1",
                               "--quiet", "-o", out));
        CHECK(r.status == 0);
        if (lit)
            CHECK(r.err[0] == '\0');
        else
            CHECK(count_char(r.err, '\n') == 1 &&
                  strstr(r.err, "dark.rib: the scene has no lights") &&
                  strstr(r.err, "--default-light"));
        int w = 0, h = 0;
        float *px = NULL;
        char err[256];
        CHECK(image_read_exr(out, &w, &h, &px, err, sizeof err) == RAYES_OK);
        double sum = 0.0;
        for (int i = 0; px && i < w * h; i++)
            sum += px[4 * i];
        mean[lit] = px ? (float)(sum / (w * h)) : -1.0f;
        free(px);
    }
    CHECK(mean[0] == 0.0f && mean[1] > 0.02f);
}

/* The mean red of an EXR, -1 when it cannot be read. */
static double exr_mean_red(const char *path)
{
    int w = 0, h = 0;
    float *px = NULL;
    char err[256];
    if (image_read_exr(path, &w, &h, &px, err, sizeof err) != RAYES_OK || !px)
        return -1.0;
    double sum = 0.0;
    for (int i = 0; i < w * h; i++)
        sum += px[4 * i];
    free(px);
    return sum / (w * h);
}

/* A closed room seen from inside, with no lights: OBJ's default light and
 * --default-light's headlight light its walls (any light that casts
 * shadows from outside, or from behind the camera, leaves it black), and
 * the OBJ's default light is its key light again once the view is outside. */
static void test_default_light_inside(void)
{
    static Run r;
    setup();
    static const char *cube = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                              "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                              "f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n";
    test_write_text(SCRATCH_DIR "/room.obj", cube);
    test_write_text(SCRATCH_DIR "/room.rib",
                    "Projection \"perspective\" \"fov\" 60\nWorldBegin\nSurface \"matte\"\n"
                    "Scale 2 2 2\nPolygon \"P\" [-1 -1 1 1 -1 1 1 1 1 -1 1 1]\n"
                    "Polygon \"P\" [-1 -1 -1 -1 1 -1 1 1 -1 1 -1 -1]\n"
                    "Polygon \"P\" [-1 -1 -1 1 -1 -1 1 -1 1 -1 -1 1]\n"
                    "Polygon \"P\" [-1 1 -1 -1 1 1 1 1 1 1 1 -1]\n"
                    "Polygon \"P\" [-1 -1 -1 -1 -1 1 -1 1 1 -1 1 -1]\n"
                    "Polygon \"P\" [1 -1 -1 1 1 -1 1 1 1 1 -1 1]\nWorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/room.obj", "--res", "16", "--spp", "1", "--quiet",
             "--look-from", "0.2,0.1,0.5", "--look-at", "0,-0.3,-1", "-o",
             SCRATCH_DIR "/room_obj.exr"));
    CHECK(r.status == 0);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/room.rib", "--res", "16", "--spp", "1", "--quiet",
             "--default-light", "-o", SCRATCH_DIR "/room_rib.exr"));
    CHECK(r.status == 0);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/room.obj", "--res", "16", "--spp", "1", "--quiet",
             "--look-from", "0.2,0.1,5", "--look-at", "0,0,0", "-o",
             SCRATCH_DIR "/room_outside.exr"));
    CHECK(r.status == 0);
    double obj = exr_mean_red(SCRATCH_DIR "/room_obj.exr");
    double rib = exr_mean_red(SCRATCH_DIR "/room_rib.exr");
    double outside = exr_mean_red(SCRATCH_DIR "/room_outside.exr");
    printf("  mean red inside: OBJ's default light %.4f, --default-light %.4f; outside %.4f\n", obj,
           rib, outside);
    CHECK(obj > 0.2 && rib > 0.2 && outside > 0.05);
}

/* --look-from, --look-at, --up and --fov replace the scene's camera: a
 * matte sphere 5 units ahead under a headlight looks the same from behind
 * it as from the file's camera, a view turned away from it is black, and a
 * malformed point is a usage error. */
static void test_camera_options(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/ahead.rib", "Projection \"perspective\" \"fov\" 40\n"
                                              "WorldBegin\nTranslate 0 0 5\nSurface \"matte\"\n"
                                              "Sphere 1 -1 1 360\nWorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/ahead.rib", "--res", "24", "--spp", "4", "--quiet",
             "--default-light", "-o", SCRATCH_DIR "/file_camera.exr"));
    CHECK(r.status == 0);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/ahead.rib", "--res", "24", "--spp", "4", "--quiet",
             "--default-light", "--look-from", "0,0,10", "--look-at", "0,0,5", "--up", "0,1,0",
             "--fov", "40", "-o", SCRATCH_DIR "/behind.exr"));
    CHECK(r.status == 0);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/ahead.rib", "--res", "24", "--spp", "4", "--quiet",
             "--default-light", "--look-at", "0,0,-5", "-o", SCRATCH_DIR "/away.exr"));
    CHECK(r.status == 0);
    double file = exr_mean_red(SCRATCH_DIR "/file_camera.exr");
    double behind = exr_mean_red(SCRATCH_DIR "/behind.exr");
    double away = exr_mean_red(SCRATCH_DIR "/away.exr");
    printf("  mean red: the file's camera %.4f, from behind %.4f, turned away %.4f\n", file, behind,
           away);
    CHECK(file > 0.05 && fabs(behind - file) < 0.01 * file && away == 0.0);
    /* the view kept (--fov alone) keeps the image: a sphere right of the
     * view stays on the right (RIB's left-handed camera is not mirrored),
     * and a moving camera is replaced by the still one given */
    test_write_text(SCRATCH_DIR "/side.rib",
                    "Projection \"perspective\" \"fov\" 40\nShutter 0 1\n"
                    "MotionBegin [0 1]\nTranslate 0 0 0\nTranslate 0 3 0\nMotionEnd\n"
                    "WorldBegin\nTranslate 0 0 5\nSurface \"matte\"\n"
                    "AttributeBegin\nTranslate 1.2 0 0\nSphere 0.6 -0.6 0.6 360\nAttributeEnd\n"
                    "WorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/side.rib", "--res", "32", "--spp", "4", "--quiet",
             "--default-light", "--fov", "40", "-o", SCRATCH_DIR "/side.exr"));
    CHECK(r.status == 0);
    {
        int w = 0, h = 0;
        float *px = NULL;
        char err[256];
        double half[2] = {0, 0};
        CHECK(image_read_exr(SCRATCH_DIR "/side.exr", &w, &h, &px, err, sizeof err) == RAYES_OK);
        for (int y = 0; px && y < h; y++)
            for (int x = 0; x < w; x++)
                half[x >= w / 2] += px[4 * (y * w + x)];
        free(px);
        printf("  the sphere right of the view: left half %.3f, right half %.3f\n", half[0],
               half[1]);
        /* still (not moved 3 units up by the file's camera motion) and not mirrored */
        CHECK(half[1] > 10.0 * half[0] + 0.5);
    }
    expect_error(2, NULL, ARGS("render", SCRATCH_DIR "/ahead.rib", "--look-from", "1,2"),
                 ARGS("--look-from: expected X,Y,Z"));
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/ahead.rib", "--quiet", "--look-from", "0,0,5", "--look-at",
             "0,0,5", "-o", SCRATCH_DIR "/none.exr"));
    CHECK(r.status == 1 && strstr(r.err, "the command line's camera") &&
          !exists(SCRATCH_DIR "/none.exr"));
}

static void test_convert(void)
{
    static Run r;
    setup();
    remove(SCRATCH_DIR "/cornell.rib");
    run(&r, NULL, ARGS("convert", "cornell", SCRATCH_DIR "/cornell.rib", "--quiet"));
    CHECK(r.status == 0 && r.err[0] == '\0' && r.out[0] == '\0');
    static char rib[65536];
    read_file(SCRATCH_DIR "/cornell.rib", rib, sizeof rib);
    CHECK(strncmp(rib, "##RenderMan RIB\n", 16) == 0);
    CHECK(strstr(rib, "WorldBegin\n") && strstr(rib, "AreaLightSource") &&
          strstr(rib, "WorldEnd\n"));
    CHECK(!scratch_has(".tmp."));
    /* the converted scene renders the same bytes as the built-in one (its
     * red wall, not planar, stays a bilinear patch rather than becoming two
     * triangles) */
    run(&r, NULL,
        ARGS("render", "cornell", "--res", "24", "--spp", "2", "--bounces", "1", "--threads", "2",
             "--quiet", "-o", SCRATCH_DIR "/builtin.exr"));
    CHECK(r.status == 0);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/cornell.rib", "--res", "24", "--spp", "2", "--bounces", "1",
             "--threads", "2", "--quiet", "-o", SCRATCH_DIR "/converted.exr"));
    CHECK(r.status == 0);
    CHECK(same_file(SCRATCH_DIR "/builtin.exr", SCRATCH_DIR "/converted.exr"));
    /* a scene file converts too, and says what it wrote */
    test_write_text(SCRATCH_DIR "/room.obj", OBJ_SCENE);
    run(&r, NULL, ARGS("convert", SCRATCH_DIR "/room.obj", SCRATCH_DIR "/room.rib"));
    CHECK(r.status == 0 && strstr(r.out, "room.rib") != NULL);
    CHECK(file_size(SCRATCH_DIR "/room.rib") > 100);
    expect_error(2, NULL, ARGS("convert", "cornell", SCRATCH_DIR "/c.txt"), ARGS(".rib"));
    expect_error(2, NULL, ARGS("convert", "cornell"), ARGS("OUT.rib"));
    expect_error(2, NULL, ARGS("convert", "nosuchscene", SCRATCH_DIR "/n.rib"),
                 ARGS("nosuchscene"));
    expect_error(1, NULL, ARGS("convert", "cornell", SCRATCH_DIR "/missing-dir/c.rib"),
                 ARGS(SCRATCH_DIR "/missing-dir/c.rib"));
    CHECK(!exists(SCRATCH_DIR "/n.rib") && !exists(SCRATCH_DIR "/c.txt"));
}

/* A bad scene file: one line with file:line:col, status 1, nothing left. */
static void test_bad_scene_file(void)
{
    setup();
    test_write_text(SCRATCH_DIR "/bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    remove(SCRATCH_DIR "/bad.png");
    remove(SCRATCH_DIR "/bad.rib");
    expect_error(1, NULL,
                 ARGS("render", SCRATCH_DIR "/bad.obj", "--res", "8", "--quiet", "-o",
                      SCRATCH_DIR "/bad.png"),
                 ARGS(SCRATCH_DIR "/bad.obj:4:7:", "vertex index"));
    CHECK(!exists(SCRATCH_DIR "/bad.png") && !exists(SCRATCH_DIR "/bad.exr"));
    expect_error(1, NULL, ARGS("convert", SCRATCH_DIR "/bad.obj", SCRATCH_DIR "/bad.rib"),
                 ARGS(SCRATCH_DIR "/bad.obj:4:7:"));
    CHECK(!exists(SCRATCH_DIR "/bad.rib") && !scratch_has(".tmp."));
    expect_error(1, NULL, ARGS("render", SCRATCH_DIR "/none.obj", "--res", "8"),
                 ARGS(SCRATCH_DIR "/none.obj"));
    CHECK(!exists(SCRATCH_DIR "/none.exr"));
}

/* --frames renders a RIB file's frames one after another into '#'
 * names; --skip-existing leaves done frames alone; a list without '#'
 * in -o, a bad list and a missing frame fail. --crop writes the window:
 * a PNG of its size, an EXR whose data window is it. */
static void test_frames_and_crop(void)
{
    static Run r;
    setup();
    char rib[2048] = "Format 24 16 1\n";
    for (int f = 1; f <= 3; f++) {
        char frame[256];
        snprintf(frame, sizeof frame,
                 "FrameBegin %d\nWorldBegin\nLightSource \"distantlight\" 1\n"
                 "Translate %d 0 5\nSphere 1 -1 1 360\nWorldEnd\nFrameEnd\n",
                 f, f - 2);
        strcat(rib, frame);
    }
    test_write_text(SCRATCH_DIR "/frames.rib", rib);
    for (int f = 1; f <= 3; f++) {
        char path[256];
        snprintf(path, sizeof path, SCRATCH_DIR "/fr.%04d.png", f);
        unlink(path);
    }
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/frames.rib", "--frames", "1-3", "--spp", "1",
                       "-o", SCRATCH_DIR "/fr.####.png"));
    CHECK(r.status == 0);
    CHECK(exists(SCRATCH_DIR "/fr.0001.png") && exists(SCRATCH_DIR "/fr.0002.png") &&
          exists(SCRATCH_DIR "/fr.0003.png"));
    int w = 0, h = 0;
    float *a = NULL, *b = NULL;
    char err[256];
    CHECK(image_read_png(SCRATCH_DIR "/fr.0001.png", &w, &h, &a, err, sizeof err) == RAYES_OK);
    CHECK(image_read_png(SCRATCH_DIR "/fr.0003.png", &w, &h, &b, err, sizeof err) == RAYES_OK);
    CHECK(a && b && w == 24 && h == 16 && memcmp(a, b, sizeof(float) * 4 * 24 * 16) != 0);
    free(a), free(b);
    long size = file_size(SCRATCH_DIR "/fr.0002.png");
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/frames.rib", "--frames", "1,2-3x1", "--spp", "1",
                       "--skip-existing", "-o", SCRATCH_DIR "/fr.####.png"));
    CHECK(r.status == 0 && strstr(r.out, "skipped") && count_char(r.out, '\n') == 3);
    CHECK(file_size(SCRATCH_DIR "/fr.0002.png") == size);
    expect_error(2, NULL, ARGS("render", SCRATCH_DIR "/frames.rib", "--frames", "1-3", "-o",
                               SCRATCH_DIR "/fr.png"),
                 ARGS("--frames", "#"));
    expect_error(2, NULL, ARGS("render", SCRATCH_DIR "/frames.rib", "--frames", "3-1"),
                 ARGS("--frames", "3-1"));
    expect_error(1, NULL, ARGS("render", SCRATCH_DIR "/frames.rib", "--frames", "7", "-o",
                               SCRATCH_DIR "/fr.#.png"),
                 ARGS("frames.rib", "no frame 7"));
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/frames.rib", "--frames", "2-3", "--spp", "1",
                       "--progress", "json", "-o", SCRATCH_DIR "/js.#.png"));
    CHECK(r.status == 0 && r.err[0] == '\0');
    CHECK(strstr(r.out, "{\"event\": \"progress\", \"frame\": 2, \"fraction\": 1.0000,") != NULL);
    CHECK(strstr(r.out, "{\"event\": \"frame\", \"frame\": 3, \"status\": 0,") != NULL);
    CHECK(strstr(r.out, "js.3.png\"]}\n") != NULL);
    CHECK(strstr(r.out, "wrote") == NULL); /* no human summary among the JSON */
    expect_error(2, NULL, ARGS("render", "cornell", "--progress", "xml"), ARGS("--progress"));
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/frames.rib", "--frame", "2", "--spp", "1",
                       "--quiet", "--crop", "0.25,0.75,0,0.5", "-o", SCRATCH_DIR "/crop.png",
                       "-o", SCRATCH_DIR "/crop.exr"));
    CHECK(r.status == 0);
    CHECK(image_read_png(SCRATCH_DIR "/crop.png", &w, &h, &a, err, sizeof err) == RAYES_OK);
    CHECK(w == 12 && h == 8);
    free(a);
    CHECK(image_read_exr(SCRATCH_DIR "/crop.exr", &w, &h, &a, err, sizeof err) == RAYES_OK);
    CHECK(w == 12 && h == 8); /* the data window */
    free(a);
    expect_error(2, NULL, ARGS("render", "cornell", "--crop", "0.5,0.2,0,1"), ARGS("--crop"));
}

/* Imager "background": the image over its colour, before the exposure;
 * the sphere keeps its own colour. */
static void test_background_imager(void)
{
    static Run r;
    setup();
    test_write_text(
        SCRATCH_DIR "/bg.rib",
        "Format 16 16 1\nExposure 1 2\nImager \"background\" \"color bgcolor\" [0.25 0 1]\n"
        "WorldBegin\nSurface \"constant\"\nColor [0 1 0]\nTranslate 0 0 5\n"
        "Sphere 0.5 -0.5 0.5 360\nWorldEnd\n");
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/bg.rib", "--spp", "4", "--quiet", "-o",
             SCRATCH_DIR "/bg.exr"));
    CHECK(r.status == 0);
    int w = 0, h = 0;
    float *px = NULL;
    char err[256];
    CHECK(image_read_exr(SCRATCH_DIR "/bg.exr", &w, &h, &px, err, sizeof err) == RAYES_OK);
    if (px && w == 16 && h == 16) {
        const float *corner = px, *mid = px + 4 * (8 * 16 + 8);
        CHECK_NEAR(corner[0], 0.5, 1e-4); /* 0.25 ^ (1 / 2) */
        CHECK_NEAR(corner[1], 0.0, 1e-6);
        CHECK_NEAR(corner[2], 1.0, 1e-4);
        CHECK_NEAR(corner[3], 1.0, 0);
        CHECK(mid[1] > 0.99f && mid[0] < 0.01f && mid[3] == 1.0f);
    }
    free(px);
}

/* The colour type byte of a PNG's header (2 RGB, 6 RGBA), -1 if none. */
static int png_colour_type(const char *path)
{
    unsigned char head[26];
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(head, 1, sizeof head, f) : 0;
    if (f)
        fclose(f);
    return n == sizeof head && memcmp(head + 12, "IHDR", 4) == 0 ? head[25] : -1;
}

/* A display of mode "rgb" writes R, G, B only (the background black, as
 * RenderMan writes it), one of mode "rgba" and -o keep alpha. */
static void test_display_modes(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/modes.rib",
                    "Format 8 8 1\nDisplay \"" SCRATCH_DIR "/modes-rgb.png\" \"file\" \"rgb\"\n"
                    "Display \"+" SCRATCH_DIR "/modes-rgba.png\" \"file\" \"rgba\"\n"
                    "Display \"+" SCRATCH_DIR "/modes-rgb.exr\" \"file\" \"rgb\"\n"
                    "WorldBegin\nSurface \"constant\"\nTranslate 0 0 5\nSphere 0.5 -0.5 0.5 360\n"
                    "WorldEnd\n");
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/modes.rib", "--spp", "1", "--quiet"));
    CHECK(r.status == 0);
    CHECK(png_colour_type(SCRATCH_DIR "/modes-rgb.png") == 2);
    CHECK(png_colour_type(SCRATCH_DIR "/modes-rgba.png") == 6);
    int w = 0, h = 0;
    float *px = NULL;
    char err[256];
    CHECK(image_read_exr(SCRATCH_DIR "/modes-rgb.exr", &w, &h, &px, err, sizeof err) == RAYES_OK);
    CHECK(px && w == 8 && h == 8 && px[0] == 0.0f && px[3] == 1.0f); /* black, opaque */
    free(px);
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/modes.rib", "--spp", "1", "--quiet", "-o",
             SCRATCH_DIR "/modes-o.png"));
    CHECK(r.status == 0 && png_colour_type(SCRATCH_DIR "/modes-o.png") == 6);
}

/* The EXR channels oiiotool lists for path ("" when it is not installed). */
static void exr_channels(const char *path, char *out, size_t size)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "oiiotool --info -v %s 2>/dev/null | grep 'channel list'", path);
    FILE *p = popen(cmd, "r");
    size_t n = p ? fread(out, 1, size - 1, p) : 0;
    out[n] = '\0';
    if (p)
        pclose(p);
}

/* AOVs: --aov's beside the colour of -o's EXR; a display whose mode names
 * AOVs writes them, alone or beside colour; a PNG or an unknown mode is
 * warned of; bad lists and --aov with --checkpoint are usage errors. */
static void test_aovs(void)
{
    static Run r;
    setup();
    test_write_text(SCRATCH_DIR "/aov.rib",
                    "Format 16 12 1\nDisplay \"" SCRATCH_DIR
                    "/aov-beauty.exr\" \"openexr\" \"rgba\"\n"
                    "Display \"+" SCRATCH_DIR "/aov-z.exr\" \"openexr\" \"z\"\n"
                    "Display \"+" SCRATCH_DIR "/aov-np.exr\" \"openexr\" \"normal N,rgb\"\n"
                    "Display \"+" SCRATCH_DIR "/aov-n.png\" \"png\" \"N\"\n"
                    "Display \"+" SCRATCH_DIR "/aov-d.exr\" \"openexr\" \"color diffuse\"\n"
                    "Display \"+" SCRATCH_DIR "/aov-ci.exr\" \"openexr\" "
                    "\"Ci,a,mse,albedo,albedo_var,diffuse,diffuse_mse,specular,zfiltered,normal\"\n"
                    "Projection \"perspective\" \"fov\" 40\n"
                    "WorldBegin\nTranslate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n");
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/aov.rib", "--spp", "1", "--quiet", "--aov", "id"));
    CHECK(r.status == 0);
    CHECK(strstr(r.err, "aov-n.png") && strstr(r.err, "EXR files only"));
    CHECK(strstr(r.err, "color diffuse") && strstr(r.err, "not rendered"));
    CHECK(strstr(r.err, "\"mse\", \"albedo_var\"")); /* one line for the display */
    CHECK(access(SCRATCH_DIR "/aov-z.exr", F_OK) == 0 &&
          access(SCRATCH_DIR "/aov-n.png", F_OK) != 0);
    CHECK(access(SCRATCH_DIR "/aov-d.exr", F_OK) != 0);
    int w = 0, h = 0;
    float *px = NULL;
    char err[256], ch[1024];
    CHECK(image_read_exr(SCRATCH_DIR "/aov-np.exr", &w, &h, &px, err, sizeof err) == RAYES_OK);
    CHECK(w == 16 && h == 12);
    free(px);
    exr_channels(SCRATCH_DIR "/aov-z.exr", ch, sizeof ch);
    if (ch[0]) { /* oiiotool is installed */
        CHECK(strstr(ch, "Z") && !strstr(ch, "R"));
        exr_channels(SCRATCH_DIR "/aov-np.exr", ch, sizeof ch);
        CHECK(strstr(ch, "N.X") && strstr(ch, "B") && !strstr(ch, "A") && strstr(ch, "id"));
        exr_channels(SCRATCH_DIR "/aov-beauty.exr", ch, sizeof ch);
        CHECK(strstr(ch, "id") && strstr(ch, "A") && !strstr(ch, "Z"));
        exr_channels(SCRATCH_DIR "/aov-ci.exr", ch, sizeof ch); /* RIS's denoiser display */
        CHECK(strstr(ch, "R") && strstr(ch, "A") && strstr(ch, "Z") && strstr(ch, "N.X") &&
              strstr(ch, "albedo.G"));
    }
    run(&r, NULL,
        ARGS("render", SCRATCH_DIR "/aov.rib", "--spp", "1", "--quiet", "--aov", "z,P", "-o",
             SCRATCH_DIR "/aov-o.exr", "-o", SCRATCH_DIR "/aov-o.png"));
    CHECK(r.status == 0 && access(SCRATCH_DIR "/aov-o.png", F_OK) == 0);
    exr_channels(SCRATCH_DIR "/aov-o.exr", ch, sizeof ch);
    if (ch[0])
        CHECK(strstr(ch, "Z") && strstr(ch, "P.Z") && strstr(ch, "R") && !strstr(ch, "N.X"));
    run(&r, NULL, ARGS("render", SCRATCH_DIR "/aov.rib", "--aov", "z,depth"));
    CHECK(r.status == 2 && strstr(r.err, "depth"));
}

TEST_MAIN(TEST(test_version_and_help), TEST(test_no_arguments), TEST(test_usage_errors),
          TEST(test_missing_data), TEST(test_render_outputs), TEST(test_render_summary),
          TEST(test_data_from_environment), TEST(test_unwritable_output), TEST(test_shader_path),
          TEST(test_render_obj), TEST(test_rib_grid_size), TEST(test_spp_over_file_sampling),
          TEST(test_png_curve), TEST(test_rib_opacity_cache_memory), TEST(test_vertex_budget),
          TEST(test_null_displacement), TEST(test_default_light), TEST(test_default_light_inside),
          TEST(test_camera_options), TEST(test_convert), TEST(test_bad_scene_file),
          TEST(test_frames_and_crop), TEST(test_background_imager), TEST(test_display_modes),
          TEST(test_light_shadows_attribute), TEST(test_quiet_requests),
          TEST(test_res_width_keeps_aspect), TEST(test_aovs))
