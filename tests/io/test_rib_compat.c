/*
 * Classic RIB files as RenderMan reads them (io/rib.c, rib_state.c,
 * rib_shade.c, rib_prim.c): requests RenderMan accepts that used to stop
 * a file (GeometricRepresentation, Illuminate of a light that was
 * skipped, Hider counts of 0, ri.h's "wrap" and "nowrap", RenderMan 20's
 * Procedural2 "DelayedReadArchive2", zip archives "file.zip!member");
 * the classic lights' units (matte
 * facing a pointlight of intensity 16 at 4 units shades to exactly Cs, as
 * diffuse() has no 1/pi).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zlib.h>

#include "image/image.h"
#include "io/rib.h"
#include "rayes/rayes.h"
#include "record_sink.h"
#include "test.h"

static Record rec;
static IoSettings settings;
static char err[1024];

static RayesError rib(const char *text)
{
    return record_rib_said(&rec, text, &settings, err, sizeof err);
}

#define WORLD(body) "Projection \"perspective\" \"fov\" 40\nWorldBegin\n" body "\nWorldEnd\n"
#define DISTANT "LightSource \"distantlight\" 2 \"from\" [0 0 -1] \"to\" [0 0 0]\n"
#define QUAD "Polygon \"P\" [0 0 1 1 0 1 1 1 1 0 1 1]\n"

static void test_requests_renderman_accepts(void)
{
    (void)rec_param;
    CHECK(rib(WORLD("GeometricRepresentation \"primitive\"\n" QUAD)) == RAYES_OK);
    CHECK(rec.n_mesh == 1);
    CHECK(rib(WORLD("GeometricRepresentation \"lines\"\n" QUAD)) == RAYES_OK && rec.n_mesh == 1);
    CHECK(rib(WORLD("GeometricRepresentation\n" QUAD)) != RAYES_OK); /* no name */
    /* a light rayes skips, then Illuminate of it: the rest still lights */
    CHECK(rib(WORLD("LightSource \"attenlight\" 1 \"intensity\" 1\nIlluminate 1 1\n" DISTANT
                    "Illuminate 7 0\n" QUAD)) == RAYES_OK);
    CHECK(rec.n_light == 1 && rec.n_mesh == 1);
    /* Hider counts of 0: RenderMan's own choice (RenderMan for Maya) */
    CHECK(rib("Hider \"raytrace\" \"int minsamples\" [0] \"int maxsamples\" [64]\n" WORLD(QUAD)) ==
          RAYES_OK);
    CHECK(settings.spp <= 0 && settings.max_spp == 64);
    CHECK(rib("Hider \"raytrace\" \"int minsamples\" [-1]\n" WORLD(QUAD)) != RAYES_OK);
    /* ri.h's RI_WRAP and RI_NOWRAP */
    CHECK(rib(WORLD("PatchMesh \"bilinear\" 2 \"nowrap\" 2 \"nowrap\" "
                    "\"P\" [0 0 1 1 0 1 0 1 1 1 1 1]")) == RAYES_OK);
    CHECK(rec.n_patch == 1);
    CHECK(rib(WORLD("PatchMesh \"bilinear\" 2 \"wrap\" 2 \"nowrap\" "
                    "\"P\" [0 0 1 1 0 1 0 1 1 1 1 1]")) == RAYES_OK);
    CHECK(rec.n_patch == 2); /* wrapped in u: the closing patch too */
    CHECK(rib(WORLD("PatchMesh \"bilinear\" 2 \"around\" 2 \"nowrap\" "
                    "\"P\" [0 0 1 1 0 1 0 1 1 1 1 1]")) != RAYES_OK);
    /* Aqsis's older "gridsize": a grid's two sides */
    CHECK(rib("Option \"limits\" \"gridsize\" [32 32]\n" WORLD(QUAD)) == RAYES_OK);
    CHECK(settings.grid_size == 1024);
    rib(WORLD("Curves \"linear\" [2] \"nowrap\" \"P\" [0 0 1 0 1 1] \"constantwidth\" [0.1]"));
    CHECK(strstr(err, "curves") != NULL && strstr(err, "periodic") == NULL); /* read to the sink */
}

static void test_procedural2(void)
{
    const char *path = RAYES_TEST_TMP "/compat_archive.rib";
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs(QUAD, f);
    fclose(f);
    char text[1024];
    snprintf(text, sizeof text,
             WORLD("Procedural2 \"DelayedReadArchive2\" \"SimpleBound\" \"string filename\" "
                   "[\"%s\"] \"float[6] bound\" [0 1 0 1 0 1]\n" QUAD),
             path);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_mesh == 2); /* the archive's quad and the file's */
    /* other kinds are skipped; the archive kind needs its file name */
    CHECK(rib(WORLD("Procedural2 \"DynamicLoad\" \"SimpleBound\" \"string dsoname\" [\"x.so\"]\n" QUAD)) ==
          RAYES_OK);
    CHECK(rec.n_mesh == 1);
    CHECK(rib(WORLD("Procedural2 \"DelayedReadArchive2\" \"SimpleBound\"\n")) != RAYES_OK);
    CHECK(strstr(err, "filename") != NULL);
    CHECK(rib(WORLD("Procedural2 \"DelayedReadArchive2\" \"SimpleBound\" \"string filename\" "
                    "[\"no/such.rib\"]\n")) != RAYES_OK);
    remove(path);
}

/* TextureCoordinates: st at a Patch's corners when it gives none (it was
 * read and skipped: textures on classic patches sat at (u, v)). */
static void test_texture_coordinates(void)
{
#define PATCH "Patch \"bilinear\" \"P\" [0 0 1 1 0 1 0 1 1 1 1 1]"
    CHECK(rib(WORLD("TextureCoordinates 0 0 2 0 0 2 2 2\n" PATCH)) == RAYES_OK);
    const RayesPrimvar *st = rec.n_patch == 1 ? rec_primvar(&rec.patch[0].pv, "st") : NULL;
    CHECK(st && st->count == 4);
    if (st)
        CHECK(st->data[2] == 2 && st->data[3] == 0 && st->data[6] == 2 && st->data[7] == 2);
    /* the default, or the patch's own st: as before */
    CHECK(rib(WORLD("TextureCoordinates 0 0 1 0 0 1 1 1\n" PATCH)) == RAYES_OK);
    CHECK(rec.n_patch == 1 && rec_primvar(&rec.patch[0].pv, "st") == NULL);
    CHECK(rib(WORLD("TextureCoordinates 0 0 2 0 0 2 2 2\n" PATCH " \"st\" [0 0 5 0 0 5 5 5]")) ==
          RAYES_OK);
    st = rec.n_patch == 1 ? rec_primvar(&rec.patch[0].pv, "st") : NULL;
    CHECK(st && st->data[2] == 5);
    /* an attribute: AttributeEnd restores it */
    CHECK(rib(WORLD("AttributeBegin\nTextureCoordinates 0 0 2 0 0 2 2 2\nAttributeEnd\n" PATCH)) ==
          RAYES_OK);
    CHECK(rec.n_patch == 1 && rec_primvar(&rec.patch[0].pv, "st") == NULL);
    CHECK(rib(WORLD("TextureCoordinates 0 0 1\n" PATCH)) != RAYES_OK);
#undef PATCH
}

static void put16(unsigned char *p, unsigned v)
{
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8);
}

static void put32(unsigned char *p, unsigned long v)
{
    put16(p, (unsigned)(v & 0xffff)), put16(p + 2, (unsigned)(v >> 16));
}

/* A zip file of two members, "a.rib" stored and "dir/b.rib" deflated, as
 * RenderMan for Maya packs archives; its bytes written to path. */
static void write_zip(const char *path, const char *a, const char *b)
{
    unsigned char out[4096], packed[1024];
    z_stream z = {0};
    deflateInit2(&z, 9, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY);
    z.next_in = (unsigned char *)b, z.avail_in = (uInt)strlen(b);
    z.next_out = packed, z.avail_out = sizeof packed;
    deflate(&z, Z_FINISH);
    size_t plen = sizeof packed - z.avail_out;
    deflateEnd(&z);
    const char *names[2] = {"a.rib", "dir/b.rib"};
    const unsigned char *data[2] = {(const unsigned char *)a, packed};
    size_t csize[2] = {strlen(a), plen}, usize[2] = {strlen(a), strlen(b)}, local[2], n = 0;
    for (int k = 0; k < 2; k++) { /* local headers and data */
        local[k] = n;
        unsigned char *h = out + n;
        memset(h, 0, 30);
        put32(h, 0x04034b50), put16(h + 4, 20), put16(h + 8, k ? 8 : 0);
        put32(h + 18, csize[k]), put32(h + 22, usize[k]), put16(h + 26, (unsigned)strlen(names[k]));
        n += 30;
        memcpy(out + n, names[k], strlen(names[k])), n += strlen(names[k]);
        memcpy(out + n, data[k], csize[k]), n += csize[k];
    }
    size_t dir = n;
    for (int k = 0; k < 2; k++) { /* the central directory */
        unsigned char *h = out + n;
        memset(h, 0, 46);
        put32(h, 0x02014b50), put16(h + 4, 20), put16(h + 6, 20), put16(h + 10, k ? 8 : 0);
        put32(h + 20, csize[k]), put32(h + 24, usize[k]), put16(h + 28, (unsigned)strlen(names[k]));
        put32(h + 42, local[k]);
        n += 46;
        memcpy(out + n, names[k], strlen(names[k])), n += strlen(names[k]);
    }
    unsigned char *e = out + n;
    memset(e, 0, 22);
    put32(e, 0x06054b50), put16(e + 8, 2), put16(e + 10, 2), put32(e + 12, n - dir);
    put32(e + 16, dir);
    n += 22;
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f) {
        fwrite(out, 1, n, f);
        fclose(f);
    }
}

/* ReadArchive "file.zip!member": a member of a zip file, stored or
 * deflated (RenderMan for Maya's archives were "not found"). */
static void test_zip_archives(void)
{
    const char *zip = RAYES_TEST_TMP "/compat_archives.zip";
    write_zip(zip, QUAD, QUAD QUAD);
    char text[1024];
    snprintf(text, sizeof text, WORLD("ReadArchive \"%s!a.rib\"\nReadArchive \"%s!dir/b.rib\""),
             zip, zip);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_mesh == 3); /* one quad stored, two deflated */
    snprintf(text, sizeof text, WORLD("ReadArchive \"%s!c.rib\""), zip);
    CHECK(rib(text) != RAYES_OK && strstr(err, "no such member c.rib") != NULL);
    /* a damaged or foreign file: one line, no crash */
    FILE *f = fopen(zip, "r+b");
    if (f) {
        fseek(f, -4, SEEK_END);
        fputc(0x7f, f); /* the directory's offset's high byte: far out */
        fclose(f);
    }
    snprintf(text, sizeof text, WORLD("ReadArchive \"%s!a.rib\""), zip);
    CHECK(rib(text) != RAYES_OK && strstr(err, "damaged") != NULL);
    f = fopen(zip, "wb");
    if (f) {
        fputs(QUAD, f);
        fclose(f);
    }
    CHECK(rib(text) != RAYES_OK && strstr(err, "not a zip file") != NULL);
    remove(zip);
}

/* The centre pixel of a RIB file rendered at 8 x 8, no bounces. */
static float centre(const char *text)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings st;
    io_settings_init(&st);
    IoReadOptions opt = {NULL, -1};
    float v = NAN;
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 8, o.spp = 4, o.bounces = 0, o.threads = 1;
    RayesImage *img = NULL;
    if (io_rib_parse("t.rib", (const unsigned char *)text, strlen(text), &sink, &opt, &st, err,
                     sizeof err) == RAYES_OK &&
        rayes_scene_commit(s) == RAYES_OK && rayes_render(s, &o, &img, NULL) == RAYES_OK)
        v = img->rgba[4 * (4 * 8 + 4)];
    rayes_image_free(img);
    rayes_scene_release(s);
    return v;
}

/* RenderMan's point, spot and distant lights: intensity over distance
 * squared times (L.N), no 1/pi (diffuse() in the RI spec); an
 * ambientlight's intensity is ambient() itself. */
static void test_classic_light_units(void)
{
#define LIT(light)                                                                                 \
    "Projection \"perspective\" \"fov\" 10\nWorldBegin\n" light "\n"                               \
    "Surface \"matte\"\nTranslate 0 0 5\nSphere 1 -1 1 360\nWorldEnd\n"
    CHECK_NEAR(centre(LIT("LightSource \"pointlight\" 1 \"intensity\" 16")), 1.0, 0.01);
    CHECK_NEAR(centre(LIT("LightSource \"pointlight\" 1")), 1.0 / 16, 0.001); /* default 1 */
    CHECK_NEAR(centre(LIT("LightSource \"distantlight\" 1 \"intensity\" 0.5")), 0.5, 0.01);
    CHECK_NEAR(centre(LIT("LightSource \"spotlight\" 1 \"intensity\" 8 \"to\" [0 0 1]")), 0.5,
               0.01);
    CHECK_NEAR(centre(LIT("LightSource \"ambientlight\" 1 \"intensity\" 0.25")), 0.25, 0.001);
#undef LIT
}

/* 8-bit files: classic RIB files as RenderMan writes them (linear, its
 * Exposure the curve); RenderMan 19's and later through sRGB; the file's
 * own Option "rayes" "pngcurve" over both. */
static void test_png_curve(void)
{
    CHECK(rib(WORLD(DISTANT QUAD)) == RAYES_OK && settings.png_curve == IO_CURVE_LINEAR);
    CHECK(rib(WORLD("Bxdf \"PxrDiffuse\" \"d\"\n" DISTANT QUAD)) == RAYES_OK &&
          settings.png_curve == IO_CURVE_SRGB);
    CHECK(rib("Option \"rayes\" \"string pngcurve\" [\"srgb\"]\n" WORLD(DISTANT QUAD)) ==
              RAYES_OK &&
          settings.png_curve == IO_CURVE_SRGB);
    CHECK(rib("Option \"rayes\" \"string pngcurve\" [\"linear\"]\n" WORLD(
              "Bxdf \"PxrDiffuse\" \"d\"\n" QUAD)) == RAYES_OK &&
          settings.png_curve == IO_CURVE_LINEAR);
    CHECK(rib("Option \"rayes\" \"string pngcurve\" [\"log\"]\n" WORLD(QUAD)) != RAYES_OK);
    CHECK(strstr(err, "pngcurve") != NULL);
}

/* MakeTexture and MakeLatLongEnvironment: the made name stands for the
 * picture (shader and environment map parameters get its path); a
 * picture that is not there makes nothing (a warning), the name kept. */
static void test_made_textures(void)
{
    const char *pic = RAYES_TEST_TMP "/compat_pic.png";
    static const float rgba[4] = {1, 0, 0, 1};
    char e[256], text[2048];
    CHECK(image_write_png(pic, 1, 1, rgba, e, sizeof e) == RAYES_OK);
    snprintf(text, sizeof text,
             "MakeTexture \"%s\" \"pic.tex\" \"periodic\" \"periodic\" \"gaussian\" 1 1\n"
             "MakeLatLongEnvironment \"%s\" \"sky.env\" \"gaussian\" 1 1\n" WORLD(
                 "LightSource \"environmentlight\" 1 \"string mapname\" \"sky.env\"\n"
                 "Surface \"paintedplastic\" \"texturename\" \"pic.tex\"\n" QUAD),
             pic, pic);
    CHECK(rib(text) == RAYES_OK);
    const RayesParam *tn =
        rec.n_shader > 0 ? rec_param(&rec.shader[rec.n_shader - 1], "texturename") : NULL;
    CHECK(tn && tn->string && strcmp(tn->string, pic) == 0);
    const RayesParam *mn = rec.n_light > 0 ? rec_param(&rec.light[0], "mapname") : NULL;
    CHECK(mn && mn->string && strcmp(mn->string, pic) == 0);
    CHECK(rib("MakeTexture \"nowhere.png\" \"x.tex\" \"black\" \"black\" \"box\" 1 1\n" WORLD(
              "Surface \"paintedplastic\" \"texturename\" \"x.tex\"\n" QUAD)) == RAYES_OK);
    tn = rec.n_shader > 0 ? rec_param(&rec.shader[rec.n_shader - 1], "texturename") : NULL;
    CHECK(tn && tn->string && strcmp(tn->string, "x.tex") == 0);
}

TEST_MAIN(TEST(test_requests_renderman_accepts), TEST(test_procedural2), TEST(test_made_textures),
          TEST(test_classic_light_units), TEST(test_png_curve), TEST(test_texture_coordinates),
          TEST(test_zip_archives))
