/*
 * pbrt-v4 textures through the command line: a conductor plane seen from
 * above under an environment (pbrt's infinite light with an equal-area
 * map, bright only around the zenith) whose roughness is a checkerboard
 * of a smooth and a rough value. The file reads without a warning; where
 * the checkerboard is smooth the plane renders as the all-smooth plane
 * (a mirror of the bright zenith), where it is rough as the all-rough one
 * (dim: its wide lobe mostly sees black), and both kinds of check are in
 * the picture. A textured conductor reflectance, an image map with
 * uscale and invert, a textured subsurface reflectance and a textured
 * displacement render without warnings too, the reflectances' halves in
 * their ratio, and the displaced plane differs from the flat one.
 * pbrt-v3: a z-up sky map seen along three directions, and Bitterli's
 * Cornell box in v3's words rendering the bytes of its v4 form.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "test.h"

#define TMP RAYES_TEST_TMP "/pbrt_textures"
enum { RES = 64 };

static void write_text(const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", TMP, name);
    test_write_text(path, text);
}

/* An equal-area octahedral map (pbrt-v4's infinite light), 64 x 64:
 * radiance 4 in its central 8 x 8 texels (around +z), 0 elsewhere; and a
 * 4 x 4 grey image of 0.25 on the left, 0.75 on the right. */
static void write_images(void)
{
    enum { S = 64 };
    static float sky[S * S * 4], half[4 * 4 * 4];
    for (int y = 0; y < S; y++)
        for (int x = 0; x < S; x++) {
            int in = abs(2 * x - S + 1) < 8 && abs(2 * y - S + 1) < 8;
            for (int c = 0; c < 3; c++)
                sky[4 * (y * S + x) + c] = in ? 4.0f : 0.0f;
            sky[4 * (y * S + x) + 3] = 1.0f;
        }
    for (int i = 0; i < 16; i++) {
        for (int c = 0; c < 3; c++)
            half[4 * i + c] = i % 4 < 2 ? 0.25f : 0.75f;
        half[4 * i + 3] = 1.0f;
    }
    char err[300];
    mkdir(TMP, 0755);
    CHECK(image_write_exr(TMP "/sky.exr", S, S, sky, err, sizeof err) == RAYES_OK);
    CHECK(image_write_exr(TMP "/half.exr", 4, 4, half, err, sizeof err) == RAYES_OK);
}

/* The scene with the plane's material (and textures) given. */
static void write_scene(const char *name, const char *material)
{
    char text[4096];
    snprintf(text, sizeof text,
             "LookAt 0 0 3  0 0 0  0 1 0\n"
             "Camera \"perspective\" \"float fov\" 30\n"
             "Film \"rgb\" \"integer xresolution\" %d \"integer yresolution\" %d\n"
             "WorldBegin\n"
             "LightSource \"infinite\" \"string filename\" \"sky.exr\"\n"
             "Texture \"checks\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 2\n"
             "  \"float tex1\" 0 \"float tex2\" 0.5\n"
             "Texture \"half\" \"spectrum\" \"imagemap\" \"string filename\" \"half.exr\"\n"
             "  \"float uscale\" 1 \"bool invert\" true\n"
             "Texture \"bump\" \"float\" \"scale\" \"texture tex\" \"checks\" \"float scale\" 0.4\n"
             "%s\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-1 -1 0 1 -1 0 -1 1 0 1 1 0]\n"
             "  \"integer indices\" [0 1 2 3] \"point2 uv\" [0 0 1 0 0 1 1 1]\n",
             RES, RES, material);
    write_text(name, text);
}

/* Renders a scene of TMP, which must say no warning; its pixels (NULL on
 * failure). */
static float *render(const char *name)
{
    static char err_text[8192];
    char cmd[2048], out[512], errpath[512], err[300];
    snprintf(out, sizeof out, "%s/%s.exr", TMP, name);
    snprintf(errpath, sizeof errpath, "%s/%s.err", TMP, name);
    snprintf(cmd, sizeof cmd, "cd %s && %s render %s --spp 4 --bounces 0 --quiet -o %s 2>%s", TMP,
             RAYES_BIN, name, out, errpath);
    int status = system(cmd);
    FILE *f = fopen(errpath, "r");
    size_t n = f ? fread(err_text, 1, sizeof err_text - 1, f) : 0;
    err_text[n] = '\0';
    if (f)
        fclose(f);
    CHECK(status == 0 && strstr(err_text, "warning") == NULL);
    if (strstr(err_text, "warning"))
        fprintf(stderr, "  %s: %s", name, err_text);
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

/* Mean luminance of the 12 x 12 pixels around the centre of quadrant q
 * (0 top left, 1 top right, 2 bottom left, 3 bottom right). */
static double quadrant(const float *rgba, int q)
{
    int cx = q % 2 ? 3 * RES / 4 : RES / 4, cy = q / 2 ? 3 * RES / 4 : RES / 4;
    double sum = 0;
    for (int y = cy - 6; y < cy + 6; y++)
        for (int x = cx - 6; x < cx + 6; x++)
            for (int c = 0; c < 3; c++)
                sum += rgba[4 * (y * RES + x) + c];
    return sum / (12.0 * 12.0 * 3.0);
}

static void test_textured_roughness(void)
{
    write_images();
    write_scene("checks.pbrt", "Material \"conductor\" \"rgb reflectance\" [0.9 0.9 0.9] "
                               "\"texture roughness\" \"checks\"");
    write_scene("smooth.pbrt", "Material \"conductor\" \"rgb reflectance\" [0.9 0.9 0.9]");
    write_scene("rough.pbrt", "Material \"conductor\" \"rgb reflectance\" [0.9 0.9 0.9] "
                              "\"float roughness\" 0.5");
    float *a = render("checks.pbrt"), *b = render("smooth.pbrt"), *c = render("rough.pbrt");
    if (!a || !b || !c) {
        free(a), free(b), free(c);
        return;
    }
    int as_smooth = 0, as_rough = 0;
    for (int q = 0; q < 4; q++) {
        double va = quadrant(a, q), vb = quadrant(b, q), vc = quadrant(c, q);
        printf("quadrant %d: textured %.4f, smooth %.4f, rough %.4f\n", q, va, vb, vc);
        CHECK(vb > 2.0 * vc); /* the bright zenith in the mirror, dim in the wide lobe */
        as_smooth += fabs(va - vb) < 0.1 * vb;
        as_rough += fabs(va - vc) < 0.1 * vb;
    }
    CHECK(as_smooth == 2 && as_rough == 2);
    free(a), free(b), free(c);
}

static void test_other_textured_parameters(void)
{
    write_images();
    write_scene("refl.pbrt", "Material \"conductor\" \"texture reflectance\" \"half\"");
    write_scene("flat.pbrt", "Material \"diffuse\" \"texture reflectance\" \"half\"");
    write_scene("bumped.pbrt", "Material \"diffuse\" \"texture reflectance\" \"half\" "
                               "\"texture displacement\" \"bump\"");
    float *r = render("refl.pbrt"), *f = render("flat.pbrt"), *d = render("bumped.pbrt");
    if (r && f && d) {
        /* inverted: 0.75 at u < 1/2, 0.25 beyond, which pbrt's camera
         * (looking down -z with y up) shows on the right */
        printf("reflectance: left %.3f right %.3f; diffuse: left %.3f right %.3f\n", quadrant(r, 0),
               quadrant(r, 1), quadrant(f, 0), quadrant(f, 1));
        CHECK(quadrant(r, 1) > 2.5 * quadrant(r, 0));
        CHECK(quadrant(f, 1) > 2.5 * quadrant(f, 0));
        int moved = 0;
        for (int i = 0; i < RES * RES; i++)
            moved += fabs(d[4 * i] - f[4 * i]) > 0.05 * f[4 * i] + 1e-3;
        printf("displacement: %d of %d pixels changed\n", moved, RES * RES);
        CHECK(moved > RES * RES / 50); /* the raised checks come nearer, and their walls show */
    }
    /* subsurface's textured reflectance colours each point as the diffuse
     * plane's does (the same step between the halves; the coat adds its
     * reflection of the zenith to both); it rendered white: the texture
     * was read as the default 1 */
    write_scene("skin.pbrt", "Material \"subsurface\" \"texture reflectance\" \"half\" "
                             "\"rgb mfp\" [0.05 0.05 0.05]");
    float *k = render("skin.pbrt");
    if (k && f) {
        double step = quadrant(k, 1) - quadrant(k, 0), want = quadrant(f, 1) - quadrant(f, 0);
        printf("subsurface: left %.3f right %.3f (step %.3f, diffuse %.3f)\n", quadrant(k, 0),
               quadrant(k, 1), step, want);
        CHECK(fabs(step - want) < 0.1 * want);
    }
    free(r), free(f), free(d), free(k);
}

/* pbrt-v4's planar, spherical and cylindrical mappings (kroken's book
 * covers, cups): a checkerboard of unit checks mapped by the plane's x
 * and y alternates across the quadrants (by uv, 0 to 1, it would be one
 * check); spherical and cylindrical mappings read without a warning and
 * differ from uv too. */
static void test_texture_mappings(void)
{
    write_images();
    write_scene("planar.pbrt", "Texture \"pl\" \"spectrum\" \"checkerboard\" \"string mapping\" "
                               "\"planar\" \"vector3 v1\" [1 0 0] \"vector3 v2\" [0 1 0] "
                               "\"rgb tex1\" [0.8 0.8 0.8] \"rgb tex2\" [0.1 0.1 0.1]\n"
                               "Material \"diffuse\" \"texture reflectance\" \"pl\"");
    write_scene("sph.pbrt", "Texture \"sp\" \"spectrum\" \"checkerboard\" \"string mapping\" "
                            "\"spherical\" \"float uscale\" 1 \"rgb tex1\" [0.8 0.8 0.8] "
                            "\"rgb tex2\" [0.1 0.1 0.1]\n"
                            "Material \"diffuse\" \"texture reflectance\" \"sp\"");
    write_scene("cyl.pbrt",
                "Texture \"cy\" \"spectrum\" \"checkerboard\" \"string mapping\" "
                "\"cylindrical\" \"rgb tex1\" [0.8 0.8 0.8] \"rgb tex2\" [0.1 0.1 0.1]\n"
                "Material \"diffuse\" \"texture reflectance\" \"cy\"");
    float *a = render("planar.pbrt"), *b = render("sph.pbrt"), *c = render("cyl.pbrt");
    if (a) {
        double q[4];
        for (int k = 0; k < 4; k++)
            q[k] = quadrant(a, k);
        printf("planar: %.3f %.3f / %.3f %.3f\n", q[0], q[1], q[2], q[3]);
        CHECK(fabs(q[0] - q[3]) < 0.1 * q[0] && fabs(q[1] - q[2]) < 0.1 * q[1]);
        CHECK(fmax(q[0], q[1]) > 4 * fmin(q[0], q[1])); /* 0.8 against 0.1 */
    }
    free(a), free(b), free(c);
}

/* pbrt-v3's infinite light ("mapname"): a latitude-longitude map with +z
 * up and longitude from +x toward +y. 16 x 8 texels: the upper half
 * (theta < 90 degrees) red where phi < 180 (y > 0) and green where not,
 * the lower half blue. Seen by a narrow camera looking along (1, 1, 1),
 * (1, -1, 1) and (1, 0, -1): red, green, blue. */
static void test_v3_infinite_map(void)
{
    enum { W = 16, H = 8 };
    static float map[W * H * 4];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *t = &map[4 * (y * W + x)];
            t[0] = y < H / 2 && x < W / 2 ? 1.0f : 0.0f;
            t[1] = y < H / 2 && x >= W / 2 ? 1.0f : 0.0f;
            t[2] = y >= H / 2 ? 1.0f : 0.0f;
            t[3] = 1.0f;
        }
    char err[300];
    mkdir(TMP, 0755);
    CHECK(image_write_exr(TMP "/v3sky.exr", W, H, map, err, sizeof err) == RAYES_OK);
    static const char *const look[3] = {"1 1 1", "1 -1 1", "1 0 -1"};
    for (int k = 0; k < 3; k++) {
        char text[1024], name[32];
        snprintf(text, sizeof text,
                 "LookAt 0 0 0  %s  0 0 1\nCamera \"perspective\" \"float fov\" 5\n"
                 "Film \"image\" \"integer xresolution\" %d \"integer yresolution\" %d\n"
                 "WorldBegin\nLightSource \"infinite\" \"string mapname\" \"v3sky.exr\"\n",
                 look[k], RES, RES);
        snprintf(name, sizeof name, "v3sky%d.pbrt", k);
        write_text(name, text);
        float *img = render(name);
        if (!img)
            continue;
        const float *c = &img[4 * ((RES / 2) * RES + RES / 2)];
        printf("  looking along (%s): %.3f %.3f %.3f\n", look[k], c[0], c[1], c[2]);
        CHECK(c[k] > 0.9f && c[(k + 1) % 3] < 0.1f && c[(k + 2) % 3] < 0.1f);
        free(img);
    }
}

/* text with every `from` replaced by `to` (malloc'd). */
static char *replaced(const char *text, const char *from, const char *to)
{
    size_t n = 0, lf = strlen(from), lt = strlen(to);
    for (const char *p = strstr(text, from); p; p = strstr(p + lf, from))
        n++;
    char *out = malloc(strlen(text) + n * (lt > lf ? lt - lf : 0) + 1), *o = out;
    if (!out)
        return NULL;
    for (const char *p = text;;) {
        const char *q = strstr(p, from);
        size_t k = q ? (size_t)(q - p) : strlen(p);
        memcpy(o, p, k), o += k;
        if (!q)
            break;
        memcpy(o, to, lt), o += lt;
        p = q + lf;
    }
    *o = '\0';
    return out;
}

/* Bitterli's Cornell box in pbrt-v3's words (matte and Kd, the image
 * film, xwidth, point and float uv) renders the same bytes as in pbrt-v4's
 * (diffuse and reflectance, ...). */
static void test_v3_cornell_box(void)
{
    FILE *f = fopen(RAYES_TEST_DATA "/scenes/pbrt-bitterli/cornell-box/scene-v4.pbrt", "rb");
    CHECK(f != NULL);
    if (!f)
        return;
    static char v4[65536];
    size_t n = fread(v4, 1, sizeof v4 - 1, f);
    fclose(f);
    v4[n] = '\0';
    static const char *const pairs[][2] = {{"[ 512 ]", "[ 64 ]"},
                                           {"[ \"diffuse\" ]", "[ \"matte\" ]"},
                                           {"rgb reflectance", "rgb Kd"},
                                           {"Film \"rgb\"", "Film \"image\""},
                                           {"float xradius", "float xwidth"},
                                           {"float yradius", "float ywidth"},
                                           {"point3 P", "point P"},
                                           {"point2 uv", "float uv"}};
    char *v3 = replaced(v4, pairs[0][0], pairs[0][1]), *four = v3 ? strdup(v3) : NULL;
    for (size_t k = 1; v3 && k < sizeof pairs / sizeof pairs[0]; k++) {
        char *next = replaced(v3, pairs[k][0], pairs[k][1]);
        free(v3);
        v3 = next;
    }
    CHECK(v3 && four && strstr(v3, "\"matte\"") && !strstr(v3, "reflectance"));
    mkdir(TMP, 0755);
    if (v3 && four) {
        write_text("cornell3.pbrt", v3);
        write_text("cornell4.pbrt", four);
        float *a = render("cornell3.pbrt"), *b = render("cornell4.pbrt");
        CHECK(a && b && memcmp(a, b, (size_t)RES * RES * 4 * sizeof *a) == 0);
        CHECK(a && quadrant(a, 0) > 0.03); /* lit (the red wall's corner) */
        free(a);
        free(b);
    }
    free(v3);
    free(four);
}

TEST_MAIN(TEST(test_textured_roughness), TEST(test_v3_infinite_map), TEST(test_v3_cornell_box),
          TEST(test_other_textured_parameters), TEST(test_texture_mappings))
