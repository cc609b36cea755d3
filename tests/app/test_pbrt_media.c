/*
 * pbrt-v4 media through the command line: a diffuse floor lit by a
 * distant light straight down, seen from above through a slab z in [1, 2]
 * (a box of material "interface") filled with an absorbing medium
 * (sigma_s 0). Camera rays and shadow rays each cross the slab once, so
 * the centre of the floor is exp(-2 tau) of the open floor's, tau the
 * slab's optical depth: sigma_a for "homogeneous" and for "nanovdb" (a
 * grid of one value written by nvdb_write.h, its voxel centres enclosing
 * the slab), and 0.75 sigma_a for a 1 x 1 x 1 "uniformgrid" whose box is
 * the slab in z (pbrt's grid fades to half its value at the box's faces;
 * pbrt-v3's "heterogeneous" alike). The
 * box itself is invisible; the files read without a warning. The camera's
 * medium fills the scene's bounds (exp(-sigma d) along camera and shadow
 * rays); a medium bounded by several open shapes, each naming it on
 * one side, fills what they close; a shape whose medium was never defined
 * is an error naming the line.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "nvdb_write.h"
#include "test.h"

#define TMP RAYES_TEST_TMP "/pbrt_media"
enum { RES = 32 };

/* The slab as a closed box of 12 triangles. */
static const char *const box_shape =
    "Shape \"trianglemesh\" \"point3 P\" [-5 -5 1  5 -5 1  5 5 1  -5 5 1  -5 -5 2  5 -5 2  5 5 2  "
    "-5 5 2]\n"
    "  \"integer indices\" [0 2 1 0 3 2  4 5 6 4 6 7  0 1 5 0 5 4  1 2 6 1 6 5  2 3 7 2 7 6  "
    "3 0 4 3 4 7]\n";

static void write_scene(const char *name, const char *media)
{
    char text[20000], path[512];
    snprintf(
        text, sizeof text,
        "LookAt 0 0 6  0 0 0  0 1 0\n"
        "Camera \"perspective\" \"float fov\" 10\n"
        "Film \"rgb\" \"integer xresolution\" %d \"integer yresolution\" %d\n"
        "WorldBegin\n"
        "LightSource \"distant\" \"point3 from\" [0 0 1] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n"
        "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
        "Shape \"bilinearmesh\" \"point3 P\" [-4 -4 0 4 -4 0 -4 4 0 4 4 0]\n"
        "  \"integer indices\" [0 1 2 3]\n"
        "%s",
        RES, RES, media);
    snprintf(path, sizeof path, "%s/%s", TMP, name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* Renders a scene of TMP; its standard error into err_text, its pixels
 * (NULL on failure). */
static float *render(const char *name, char *err_text, size_t size)
{
    char cmd[2048], out[512], errpath[512], err[300];
    snprintf(out, sizeof out, "%s/%s.exr", TMP, name);
    snprintf(errpath, sizeof errpath, "%s/%s.err", TMP, name);
    snprintf(cmd, sizeof cmd, "cd %s && %s render %s --spp 4 --bounces 0 --quiet -o %s 2>%s", TMP,
             RAYES_BIN, name, out, errpath);
    int status = system(cmd);
    FILE *f = fopen(errpath, "r");
    size_t n = f ? fread(err_text, 1, size - 1, f) : 0;
    err_text[n] = '\0';
    if (f)
        fclose(f);
    if (status != 0) {
        fprintf(stderr, "  %s: %s", name, err_text);
        return NULL;
    }
    int w, h;
    float *rgba = NULL;
    CHECK(image_read_exr(out, &w, &h, &rgba, err, sizeof err) == RAYES_OK);
    CHECK(w == RES && h == RES);
    return rgba;
}

/* Mean red of the 8 x 8 pixels at the centre. */
static double centre(const float *rgba)
{
    double sum = 0;
    for (int y = RES / 2 - 4; y < RES / 2 + 4; y++)
        for (int x = RES / 2 - 4; x < RES / 2 + 4; x++)
            sum += rgba[4 * (y * RES + x)];
    return sum / 64.0;
}

static void test_absorbing_slabs(void)
{
    mkdir(TMP, 0755);
    static float v[8][8][8];
    for (int i = 0; i < 512; i++)
        v[i >> 6][i >> 3 & 7][i & 7] = 1.0f;
    const double o[3] = {-7, -7, 0};
    CHECK(nvdb_write(TMP "/one.nvdb", "density", (const float(*)[8][8])v, 2.0, o) == 0);
    const float sigma = 0.4f;
    char media[5][1024];
    snprintf(media[0], sizeof media[0], "# no medium\n");
    const char *defs[4] = {
        "MakeNamedMedium \"slab\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.2 0.2 0.2]\n"
        "  \"rgb sigma_s\" [0 0 0] \"float scale\" 2\n",
        "MakeNamedMedium \"slab\" \"string type\" \"nanovdb\" \"string filename\" \"one.nvdb\"\n"
        "  \"rgb sigma_a\" [0.4 0.4 0.4] \"rgb sigma_s\" [0 0 0]\n",
        "MakeNamedMedium \"slab\" \"string type\" \"uniformgrid\" \"float density\" [2]\n"
        "  \"point3 p0\" [-50 -50 1] \"point3 p1\" [50 50 2] \"rgb sigma_a\" [0.2 0.2 0.2]\n"
        "  \"rgb sigma_s\" [0 0 0] \"float g\" 0.3\n",
        /* pbrt-v3's name for the same grid */
        "MakeNamedMedium \"slab\" \"string type\" \"heterogeneous\" \"float density\" [2]\n"
        "  \"point p0\" [-50 -50 1] \"point p1\" [50 50 2] \"color sigma_a\" [0.2 0.2 0.2]\n"
        "  \"color sigma_s\" [0 0 0] \"float g\" 0.3\n"};
    for (int k = 0; k < 4; k++)
        snprintf(media[k + 1], sizeof media[k + 1],
                 "%sAttributeBegin\nMediumInterface \"slab\" \"\"\nMaterial \"interface\"\n%s"
                 "AttributeEnd\n",
                 defs[k], box_shape);
    const double tau[5] = {0, sigma, sigma, 0.75 * sigma, 0.75 * sigma};
    const char *names[5] = {"open.pbrt", "homogeneous.pbrt", "nanovdb.pbrt", "uniformgrid.pbrt",
                            "heterogeneous.pbrt"};
    double open = 0;
    for (int k = 0; k < 5; k++) {
        char err_text[4096];
        write_scene(names[k], media[k]);
        float *img = render(names[k], err_text, sizeof err_text);
        CHECK(img != NULL && strstr(err_text, "warning") == NULL);
        if (strstr(err_text, "warning"))
            fprintf(stderr, "  %s: %s", names[k], err_text);
        if (!img)
            continue;
        double c = centre(img);
        if (k == 0)
            open = c;
        else {
            double want = exp(-2.0 * tau[k]);
            fprintf(stderr, "%s: %g of the open floor, exp(-2 tau) = %g\n", names[k], c / open,
                    want);
            CHECK(fabs(c / open - want) < 0.01 * want);
        }
        free(img);
    }
    CHECK(open > 0.1);
}

/* pbrt-v4's "cloud" medium in the slab: its density is 1 where the
 * medium's y is at most 0 (the cloud's solid bottom) and 0 at y >= 1, so
 * moved there (a Translate before MakeNamedMedium) it absorbs as the
 * homogeneous slab does, or not at all; between, its noise varies it over
 * the floor (the spread of the centre's pixels) and it absorbs less than
 * the solid bottom. Above y = 0.5 with a density of 0 it is empty (the
 * noise's term, (1 - y) 4.5 density, is 0; above y = 1 it would be
 * positive where the noise is negative, as in pbrt). Its density is in its
 * box p0..p1 alone. */
static void test_cloud(void)
{
    mkdir(TMP, 0755);
    const char *shift[4] = {"50", "-50", "-0.3", "-0.3"}; /* medium y = world y - shift */
    const char *density[4] = {"2", "0", "2", "2"};
    const char *box[4] = {"[-50 -100 1] \"point3 p1\" [50 0 2]",
                          "[-50 1 1] \"point3 p1\" [50 100 2]", "[-50 -1 1] \"point3 p1\" [50 1 2]",
                          "[-50 -1 3] \"point3 p1\" [50 1 4]"};
    double c[5], spread[5];
    for (int k = 0; k < 5; k++) {
        char media[2048], name[32], err_text[4096];
        if (k < 4)
            snprintf(
                media, sizeof media,
                "AttributeBegin\nTranslate 0 %s 0\n"
                "MakeNamedMedium \"c\" \"string type\" \"cloud\" \"point3 p0\" %s\n"
                "  \"rgb sigma_a\" [0.4 0.4 0.4] \"rgb sigma_s\" [0 0 0] \"float density\" %s\n"
                "AttributeEnd\n"
                "AttributeBegin\nMediumInterface \"c\" \"\"\nMaterial \"interface\"\n%s"
                "AttributeEnd\n",
                shift[k], box[k], density[k], box_shape);
        else
            snprintf(media, sizeof media, "# no medium\n");
        snprintf(name, sizeof name, "cloud%d.pbrt", k);
        write_scene(name, media);
        float *img = render(name, err_text, sizeof err_text);
        CHECK(img != NULL && strstr(err_text, "warning") == NULL);
        c[k] = spread[k] = 0.0;
        if (!img)
            continue;
        c[k] = centre(img);
        float lo = INFINITY, hi = -INFINITY;
        for (int y = RES / 2 - 4; y < RES / 2 + 4; y++)
            for (int x = RES / 2 - 4; x < RES / 2 + 4; x++)
                lo = fminf(lo, img[4 * (y * RES + x)]), hi = fmaxf(hi, img[4 * (y * RES + x)]);
        spread[k] = hi - lo;
        free(img);
    }
    double open = c[4], want = exp(-2.0 * 0.4);
    fprintf(stderr,
            "cloud: solid %g, empty %g, noise %g (spread %g), outside %g of the open floor\n",
            c[0] / open, c[1] / open, c[2] / open, spread[2] / open, c[3] / open);
    CHECK(open > 0.1);
    CHECK(fabs(c[0] / open - want) < 0.01 * want); /* solid */
    CHECK(fabs(c[1] / open - 1.0) < 0.005);        /* empty */
    CHECK(c[2] / open > want + 0.02 && c[2] / open < 0.99 && spread[2] > 0.01 * open);
    CHECK(fabs(c[3] / open - 1.0) < 0.005); /* the box misses the slab */
}

/* pbrt-v4's nanovdb temperature grid: the slab emits sigma_a Lescale B(T)
 * per unit length, T = (temperature - temperaturecutoff) *
 * temperaturescale and B Planck's spectrum over its peak, so the camera
 * ray through its unit depth gains Lescale B(T) (1 - exp(-sigma_a)) over
 * the same slab without the grid: linear in Lescale, red over green over
 * blue at 2000 K, near white and near 1 in luminance at 6500 K (its peak
 * in the visible), nothing at 200 K; a file without the grid emits
 * nothing and reads without a warning; grids of other names are found by
 * gridname and temperaturename. */
static void test_nanovdb_temperature(void)
{
    mkdir(TMP, 0755);
    static float d[8][8][8], t[8][8][8];
    for (int i = 0; i < 512; i++)
        d[i >> 6][i >> 3 & 7][i & 7] = 1.0f, t[i >> 6][i >> 3 & 7][i & 7] = 1000.0f;
    const double o[3] = {-7, -7, 0};
    CHECK(nvdb_write(TMP "/dens.nvdb", "density", (const float(*)[8][8])d, 2.0, o) == 0);
    CHECK(nvdb_write(TMP "/temp.nvdb", "temperature", (const float(*)[8][8])t, 2.0, o) == 0);
    CHECK(nvdb_write(TMP "/smoke.nvdb", "smoke", (const float(*)[8][8])d, 2.0, o) == 0);
    CHECK(nvdb_write(TMP "/heat.nvdb", "heat", (const float(*)[8][8])t, 2.0, o) == 0);
    /* files of both grids: two segments */
    static const char *const parts[2][3] = {
        {TMP "/fire.nvdb", TMP "/dens.nvdb", TMP "/temp.nvdb"},
        {TMP "/fire2.nvdb", TMP "/smoke.nvdb", TMP "/heat.nvdb"}};
    for (int f = 0; f < 2; f++) {
        FILE *out = fopen(parts[f][0], "wb");
        for (int k = 0; k < 2 && out; k++) {
            FILE *in = fopen(parts[f][1 + k], "rb");
            char buf[8192];
            size_t n;
            while (in && (n = fread(buf, 1, sizeof buf, in)) > 0)
                CHECK(fwrite(buf, 1, n, out) == n);
            if (in)
                fclose(in);
        }
        CHECK(out && fclose(out) == 0);
    }
    static const struct {
        const char *file, *params;
    } cases[] = {
        {"dens.nvdb", "\"float Lescale\" 1"},                              /* no grid */
        {"fire.nvdb", "\"float Lescale\" 1 \"float temperaturescale\" 2"}, /* 2000 K */
        {"fire.nvdb", "\"float Lescale\" 2 \"float temperaturescale\" 2"},
        {"fire.nvdb", "\"float Lescale\" 1 \"float temperaturescale\" 6.5"}, /* 6500 K */
        {"fire.nvdb", "\"float Lescale\" 1 \"float temperaturecutoff\" 900 "
                      "\"float temperaturescale\" 2"}, /* 200 K */
        {"fire2.nvdb", "\"string gridname\" \"smoke\" \"string temperaturename\" \"heat\" "
                       "\"float Lescale\" 1 \"float temperaturescale\" 2"}, /* 2000 K */
    };
    enum { N = sizeof cases / sizeof cases[0] };
    double rgb[N][3] = {{0}};
    for (int k = 0; k < N; k++) {
        char media[2048], name[64], err_text[4096];
        snprintf(media, sizeof media,
                 "MakeNamedMedium \"slab\" \"string type\" \"nanovdb\" \"string filename\" "
                 "\"%s\"\n  \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [0 0 0] %s\n"
                 "AttributeBegin\nMediumInterface \"slab\" \"\"\nMaterial \"interface\"\n%s"
                 "AttributeEnd\n",
                 cases[k].file, cases[k].params, box_shape);
        snprintf(name, sizeof name, "temperature%d.pbrt", k);
        write_scene(name, media);
        float *img = render(name, err_text, sizeof err_text);
        CHECK(img != NULL && strstr(err_text, "warning") == NULL);
        if (!img)
            continue;
        for (int c = 0; c < 3; c++) {
            for (int y = RES / 2 - 4; y < RES / 2 + 4; y++)
                for (int x = RES / 2 - 4; x < RES / 2 + 4; x++)
                    rgb[k][c] += img[4 * (y * RES + x) + c] / 64.0;
        }
        free(img);
    }
    double gain = 1.0 - exp(-1.0), B[N][3];
    for (int k = 1; k < N; k++)
        for (int c = 0; c < 3; c++)
            B[k][c] = (rgb[k][c] - rgb[0][c]) / gain; /* Lescale B(T) */
    fprintf(stderr, "B(2000 K) = %g %g %g, B(6500 K) = %g %g %g, B(200 K) = %g\n", B[1][0], B[1][1],
            B[1][2], B[3][0], B[3][1], B[3][2], B[4][0]);
    CHECK(rgb[0][0] > 0.03); /* the lit floor through the slab, no emission */
    CHECK(B[1][0] > B[1][1] && B[1][1] > B[1][2] && B[1][2] >= 0.0 && B[1][0] > 0.01);
    for (int c = 0; c < 3; c++) {
        CHECK_NEAR(B[2][c], 2.0 * B[1][c], 2e-3 * rgb[2][c]); /* the floor's march noise */
        CHECK(fabs(B[4][c]) < 1e-4);
    }
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(B[5][c], B[1][c], 1e-6 + 1e-3 * rgb[1][c]);
    double Y = 0.2126 * B[3][0] + 0.7152 * B[3][1] + 0.0722 * B[3][2];
    CHECK(Y > 0.8 && Y < 1.0);
    CHECK(fabs(B[3][0] - B[3][2]) < 0.15 * Y && fabs(B[3][1] - B[3][2]) < 0.15 * Y);
}

/* The camera's medium (MediumInterface before Camera) fills the scene's
 * bounds and the eye: looking straight down at the floor 6 below through
 * absorbing fog, the camera ray crosses 6 and the shadow ray to the
 * distant light straight up crosses the 6 to the box's top (a thousandth
 * of its diagonal above the eye), so the centre is exp(-sigma (6 + 6 +
 * pad)) of the open floor's. A shape in the camera's medium reads without
 * a warning. */
static void test_camera_medium(void)
{
    mkdir(TMP, 0755);
    char text[4096], err_text[4096];
    write_scene("cam-open.pbrt", "# no medium\n");
    float *open = render("cam-open.pbrt", err_text, sizeof err_text);
    snprintf(text, sizeof text,
             "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.05 0.05 "
             "0.05]\n  \"rgb sigma_s\" [0 0 0]\n"
             "MediumInterface \"\" \"fog\"\n"
             "LookAt 0 0 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 10\n"
             "Film \"rgb\" \"integer xresolution\" %d \"integer yresolution\" %d\n"
             "WorldBegin\n"
             "LightSource \"distant\" \"point3 from\" [0 0 1] \"point3 to\" [0 0 0] \"rgb L\" [3 3 "
             "3]\n"
             "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-4 -4 0 4 -4 0 -4 4 0 4 4 0]\n"
             "  \"integer indices\" [0 1 2 3]\n",
             RES, RES);
    FILE *f = fopen(TMP "/cam-fog.pbrt", "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    float *fog = render("cam-fog.pbrt", err_text, sizeof err_text);
    CHECK(open != NULL && fog != NULL);
    CHECK(strstr(err_text, "warning") == NULL);
    if (open && fog) {
        double diag = sqrt(8.0 * 8.0 * 2.0 + 6.0 * 6.0), pad = 1e-3 * diag;
        double want = exp(-0.05 * (6.0 + 6.0 + pad)), got = centre(fog) / centre(open);
        fprintf(stderr, "camera medium: %g of the open floor, expected %g\n", got, want);
        CHECK(fabs(got - want) < 0.01 * want);
    }
    free(open);
    free(fog);
    /* emitters are shapes too: the camera's medium spans a scene of one
     * emitting floor (before, only the eye: no fog at all) */
    const char *emit_scene =
        "LookAt 0 0 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 10\n"
        "Film \"rgb\" \"integer xresolution\" %d \"integer yresolution\" %d\n"
        "WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
        "Shape \"bilinearmesh\" \"point3 P\" [-4 -4 0 4 -4 0 -4 4 0 4 4 0]\n"
        "  \"integer indices\" [0 1 2 3]\n";
    for (int fogged = 0; fogged < 2; fogged++) {
        char body[2048];
        snprintf(body, sizeof body, emit_scene, RES, RES);
        snprintf(text, sizeof text, "%s%s",
                 fogged ? "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" "
                          "[0.05 0.05 0.05] \"rgb sigma_s\" [0 0 0]\nMediumInterface \"\" \"fog\"\n"
                        : "",
                 body);
        f = fopen(fogged ? TMP "/cam-emit-fog.pbrt" : TMP "/cam-emit.pbrt", "w");
        if (f) {
            fputs(text, f);
            fclose(f);
        }
    }
    float *lit = render("cam-emit.pbrt", err_text, sizeof err_text);
    float *lit_fog = render("cam-emit-fog.pbrt", err_text, sizeof err_text);
    CHECK(lit != NULL && lit_fog != NULL);
    if (lit && lit_fog) {
        double pad = 1e-3 * sqrt(8.0 * 8.0 * 2.0 + 6.0 * 6.0);
        double want = exp(-0.05 * (6.0 + pad)), got = centre(lit_fog) / centre(lit);
        CHECK(fabs(got - want) < 0.01 * want);
        if (fabs(got - want) >= 0.01 * want)
            fprintf(stderr, "emitter in fog: %g of the open one, expected %g\n", got, want);
    }
    free(lit);
    free(lit_fog);
    /* pbrt's films have no alpha: the environment is written opaque, as
     * pbrt shows it (before, alpha 0 there: viewers showed a checkerboard) */
    snprintf(text, sizeof text,
             "LookAt 0 0 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 10\n"
             "Film \"rgb\" \"integer xresolution\" %d \"integer yresolution\" %d\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n"
             "Shape \"sphere\" \"float radius\" 0.1\n",
             RES, RES);
    f = fopen(TMP "/env-alpha.pbrt", "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    float *env = render("env-alpha.pbrt", err_text, sizeof err_text);
    CHECK(env != NULL);
    if (env) {
        CHECK(env[3] == 1.0f && fabsf(env[0] - 0.5f) < 1e-3f); /* a corner: the environment */
        CHECK(env[4 * (RES / 2 * RES + RES / 2) + 3] == 1.0f);  /* the sphere */
    }
    free(env);
    /* a camera medium never defined: an error naming the Camera's line */
    snprintf(text, sizeof text,
             "MediumInterface \"\" \"nope\"\nLookAt 0 0 6  0 0 0  0 1 0\n"
             "Camera \"perspective\" \"float fov\" 10\nWorldBegin\n");
    f = fopen(TMP "/cam-nope.pbrt", "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    float *none = render("cam-nope.pbrt", err_text, sizeof err_text);
    CHECK(none == NULL);
    free(none);
    CHECK(strstr(err_text, "cam-nope.pbrt:3:1: the camera's medium \"nope\"") != NULL);
}

/* Face f (0 to 5: axis f / 2, its low side for even f) of the box
 * [lo, hi] as a pbrt quad naming the medium "slab" on the box's inside,
 * in one of six ways (style f): its corners wound out or in, by
 * ReverseOrientation, by "normal N" against the winding, or mirrored by
 * its transform (pbrt's side: the winding's normal, turned toward N when
 * given, reversed by ReverseOrientation and by a mirror). */
static void box_face(char *buf, size_t size, const float lo[3], const float hi[3], int f)
{
    int a = f / 2, b = (a + 1) % 3, c = (a + 2) % 3, high = f % 2;
    float q[4][3];
    static const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}; /* normal +axis a */
    for (int k = 0; k < 4; k++) {
        int j = high ? k : 3 - k; /* wound out: toward -axis a on the low side */
        q[k][a] = high ? hi[a] : lo[a];
        q[k][b] = corner[j][0] ? hi[b] : lo[b];
        q[k][c] = corner[j][1] ? hi[c] : lo[c];
    }
    int in = f == 1 || f == 3 || f == 5;       /* "" "slab": the normal must point in */
    int wound_in = f == 1 || f == 3 || f == 5; /* 1, 3 wound in; 5 by ReverseOrientation */
    const char *extra = "";
    char normals[256] = "";
    if (f == 2) { /* "slab" "", wound in, N out */
        wound_in = 1;
        float n = high ? 1.0f : -1.0f;
        snprintf(normals, sizeof normals, " \"normal N\" [%g %g %g %g %g %g %g %g %g %g %g %g]",
                 a == 0 ? n : 0, a == 1 ? n : 0, a == 2 ? n : 0, a == 0 ? n : 0, a == 1 ? n : 0,
                 a == 2 ? n : 0, a == 0 ? n : 0, a == 1 ? n : 0, a == 2 ? n : 0, a == 0 ? n : 0,
                 a == 1 ? n : 0, a == 2 ? n : 0);
    }
    if (f == 5) { /* "" "slab", wound out and reversed */
        wound_in = 0;
        extra = "ReverseOrientation\n";
    }
    if (f == 3) { /* "" "slab", its corners' axis b mirrored back by Scale: wound out */
        wound_in = 0;
        extra = a == 0 ? "Scale 1 -1 1\n" : a == 1 ? "Scale 1 1 -1\n" : "Scale -1 1 1\n";
        for (int k = 0; k < 4; k++)
            q[k][b] = -q[k][b];
    }
    char pts[512] = "";
    for (int k = 0; k < 4; k++) {
        int j = wound_in ? 3 - k : k;
        size_t n = strlen(pts);
        snprintf(pts + n, sizeof pts - n, "%g %g %g  ", q[j][0], q[j][1], q[j][2]);
    }
    size_t n = strlen(buf);
    snprintf(buf + n, size - n,
             "AttributeBegin\nMediumInterface \"%s\" \"%s\"\n%sMaterial \"interface\"\n"
             "Shape \"trianglemesh\" \"point3 P\" [%s]%s \"integer indices\" [0 1 2 0 2 3]\n"
             "AttributeEnd\n",
             in ? "" : "slab", in ? "slab" : "", extra, pts, normals);
}

/* The slab bounded by six open pieces, as pbrt-v4 scenes bound a liquid (a
 * flat top with the medium inside, a glass's wall with it outside): each
 * quad names the medium on one side, and together they close it. The box
 * is thin along axis k and turned so that axis k is the view's: the
 * centre's rays cross faces 2k and 2k + 1, so the three turns try the six
 * ways a face names its side (box_face). The floor is exp(-2 tau) of the
 * open one each time, as under the closed box, with no warning. */
static void test_open_pieces(void)
{
    mkdir(TMP, 0755);
    static const char *const turn[3] = {"Rotate -90 0 1 0\n", "Rotate 90 1 0 0\n", ""};
    char err_text[4096];
    write_scene("open-none.pbrt", "# no medium\n");
    float *open = render("open-none.pbrt", err_text, sizeof err_text);
    CHECK(open != NULL);
    for (int k = 0; k < 3; k++) {
        char text[16384] =
            "MakeNamedMedium \"slab\" \"string type\" \"homogeneous\"\n"
            "  \"rgb sigma_a\" [0.2 0.2 0.2] \"rgb sigma_s\" [0 0 0] \"float scale\" 2\n"
            "AttributeBegin\n";
        strcat(text, turn[k]);
        float lo[3] = {-5, -5, -5}, hi[3] = {5, 5, 5};
        lo[k] = 1, hi[k] = 2;
        for (int f = 0; f < 6; f++)
            box_face(text, sizeof text, lo, hi, f);
        strcat(text, "AttributeEnd\n");
        char name[64];
        snprintf(name, sizeof name, "open-pieces-%d.pbrt", k);
        write_scene(name, text);
        float *img = render(name, err_text, sizeof err_text);
        CHECK(img != NULL && strstr(err_text, "warning") == NULL);
        if (img && open) {
            double ratio = centre(img) / centre(open), want = exp(-2.0 * 0.4);
            fprintf(stderr,
                    "open pieces, thin along axis %d: %g of the open floor, exp(-2 tau) = %g\n", k,
                    ratio, want);
            CHECK(fabs(ratio - want) < 0.01 * want);
        }
        free(img);
    }
    free(open);
}

static void test_undefined_medium(void)
{
    mkdir(TMP, 0755);
    char err_text[4096];
    float *img;
    /* an undefined medium */
    write_scene("undefined.pbrt",
                "AttributeBegin\nMediumInterface \"smoke\" \"\"\nMaterial \"interface\"\n"
                "Shape \"sphere\"\nAttributeEnd\n");
    img = render("undefined.pbrt", err_text, sizeof err_text);
    CHECK(img == NULL);
    free(img);
    CHECK(strstr(err_text, "undefined.pbrt:12:") != NULL &&
          strstr(err_text, "the medium \"smoke\", which no MakeNamedMedium defined") != NULL);
    /* a medium named by one flat shape alone, the scene's only shape: its
     * box is widened, not an error */
    FILE *f = fopen(TMP "/flat.pbrt", "w");
    if (f) {
        fprintf(f,
                "LookAt 0 0 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 10\n"
                "Film \"rgb\" \"integer xresolution\" %d \"integer yresolution\" %d\n"
                "WorldBegin\nLightSource \"distant\" \"rgb L\" [1 1 1]\n"
                "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                "AttributeBegin\nMediumInterface \"fog\" \"\"\nMaterial \"interface\"\n"
                "Shape \"disk\" \"float radius\" 2\nAttributeEnd\n",
                RES, RES);
        fclose(f);
    }
    img = render("flat.pbrt", err_text, sizeof err_text);
    CHECK(img != NULL && strstr(err_text, "warning") == NULL);
    free(img);
}

TEST_MAIN(TEST(test_absorbing_slabs), TEST(test_cloud), TEST(test_nanovdb_temperature),
          TEST(test_camera_medium), TEST(test_open_pieces), TEST(test_undefined_medium))
