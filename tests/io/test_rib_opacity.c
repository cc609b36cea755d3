/*
 * The RIB reader's visibility and opacity attributes rendered through
 * io_sink_scene (io/rib_state.c, rib_shade.c): an object invisible to the
 * camera still casts its shadow, one invisible to transmission casts none,
 * AttributeEnd restores both; Attribute "shade" "transmissionhitmode"
 * "primitive" takes Os where "shader" runs the stainedglass shader's
 * opacity method; "opacitycache" 0 keeps an object out of the opacity
 * cache; Option "limits" "opacitycachememory" (KB) reaches IoSettings; the
 * RIB writer writes the attributes back.
 *
 * The scenes: the camera and a point light at the origin looking down +z
 * at a matte floor at z = 6; a square blocker at z = 3 whose shadow and
 * image cover the same pixels (the light is at the eye), the middle of
 * the image.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "io/rib_write.h"
#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

enum { SIZE = 24 };

static const char *const floor_rib =
    "Projection \"perspective\" \"fov\" [40]\nWorldBegin\n"
    "LightSource \"shadowpoint\" 1 \"sfpz\" \"raytrace\" \"from\" [0 0 0] \"intensity\" [36]\n"
    "Surface \"matte\"\nPolygon \"P\" [-4 -4 6  4 -4 6  4 4 6  -4 4 6]\n";

/* The floor, then blocker (RIB text ending in geometry, or ""), opacity
 * cached or not. */
static RayesImage *render_cached(const char *blocker, RayesStats **stats, int opacity_cache)
{
    char text[4096];
    snprintf(text, sizeof text, "%s%s\nWorldEnd\n", floor_rib, blocker);
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    char err[512] = "";
    RayesImage *img = NULL;
    RayesError e = io_rib_parse("opacity.rib", (const unsigned char *)text, strlen(text), &sink,
                                &opt, &settings, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "  %s\n", err);
    CHECK(e == RAYES_OK);
    if (e == RAYES_OK && rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = SIZE;
        o.spp = 1;
        o.threads = 2;
        o.bounces = 0;
        o.opacity_cache = opacity_cache;
        CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    }
    rayes_scene_release(s);
    return img;
}

static RayesImage *render_rib(const char *blocker, RayesStats **stats)
{
    return render_cached(blocker, stats, 1);
}

/* The mean of channel c over the middle 6 x 6 pixels (the blocker's). */
static double middle(const RayesImage *img, int c)
{
    double t = 0;
    for (int y = SIZE / 2 - 3; y < SIZE / 2 + 3; y++)
        for (int x = SIZE / 2 - 3; x < SIZE / 2 + 3; x++)
            t += img->rgba[4 * (y * SIZE + x) + c];
    return t / 36.0;
}

/* Equal but for rounding (another object moves the scene's bounds, and
 * with them the offset of rays leaving a surface). */
static int same(const RayesImage *a, const RayesImage *b)
{
    for (int i = 0; i < 4 * SIZE * SIZE; i++)
        if (fabsf(a->rgba[i] - b->rgba[i]) > 1e-5f)
            return 0;
    return 1;
}

#define BLOCKER "Polygon \"P\" [-0.5 -0.5 3  0.5 -0.5 3  0.5 0.5 3  -0.5 0.5 3]\n"

/* The ray mask of the object of the last primitive of a RIB text. */
static uint32_t last_mask(const char *text)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    char err[512] = "";
    CHECK(io_rib_parse("v.rib", (const unsigned char *)text, strlen(text), &sink, &opt, &settings,
                       err, sizeof err) == RAYES_OK);
    uint32_t m = s->n_prims ? s->objects[s->prims[s->n_prims - 1].object].ray_mask : 0;
    rayes_scene_release(s);
    return m;
}

static void test_visibility(void)
{
    /* The older names: "trace" is diffuse and specular, PRMan 13's
     * "indirect" diffuse alone. */
    uint32_t m = last_mask("WorldBegin\nAttribute \"visibility\" \"int indirect\" [0]\n"
                           "Sphere 1 -1 1 360\nWorldEnd\n");
    CHECK(!(m & RAYES_RAY_DIFFUSE) && (m & RAYES_RAY_SPECULAR) && (m & RAYES_RAY_CAMERA));
    m = last_mask("WorldBegin\nAttribute \"visibility\" \"int trace\" [0]\n"
                  "Sphere 1 -1 1 360\nWorldEnd\n");
    CHECK(!(m & (RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR)) && (m & RAYES_RAY_SHADOW));
    /* BMRT's casts_shadows: "none" hides the object from shadow rays, the
     * others cast them (the RenderMan Repository's scenes set it) */
    m = last_mask("WorldBegin\nAttribute \"render\" \"string casts_shadows\" [\"none\"]\n"
                  "Sphere 1 -1 1 360\nWorldEnd\n");
    CHECK(!(m & RAYES_RAY_SHADOW) && (m & RAYES_RAY_CAMERA));
    m = last_mask("WorldBegin\nDeclare \"casts_shadows\" \"string\"\n"
                  "Attribute \"render\" \"casts_shadows\" \"none\"\n"
                  "Attribute \"render\" \"casts_shadows\" \"shade\"\n"
                  "Sphere 1 -1 1 360\nWorldEnd\n");
    CHECK(m & RAYES_RAY_SHADOW);
    m = last_mask("WorldBegin\nAttribute \"render\" \"casts_shadows\" \"none\"\n"
                  "Sphere 1 -1 1 360\nWorldEnd\n");
    CHECK(!(m & RAYES_RAY_SHADOW));
    RayesImage *open = render_rib("", NULL);
    RayesImage *shadow = render_rib("AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\n"
                                    "Color [1 0 0]\n" BLOCKER "AttributeEnd\n",
                                    NULL);
    RayesImage *none = render_rib("AttributeBegin\nAttribute \"visibility\" \"int camera\" [0] "
                                  "\"int transmission\" [0]\n" BLOCKER "AttributeEnd\n",
                                  NULL);
    RayesImage *old =
        render_rib("AttributeBegin\nAttribute \"visibility\" \"int camera\" [0] "
                   "\"string transmission\" \"transparent\"\n" BLOCKER "AttributeEnd\n",
                   NULL);
    /* AttributeEnd restores the visibility: the second blocker shows */
    RayesImage *restored = render_rib("AttributeBegin\nAttribute \"visibility\" \"int camera\" [0] "
                                      "\"int transmission\" [0]\nAttributeEnd\n"
                                      "Color [1 0 0]\n" BLOCKER,
                                      NULL);
    CHECK(open && shadow && none && old && restored);
    if (open && shadow && none && old && restored) {
        CHECK(middle(open, 0) > 0.1);
        CHECK(middle(shadow, 0) == 0.0);            /* a shadow, of an unseen blocker */
        CHECK(same(none, open) && same(old, open)); /* no shadow, nothing seen */
        CHECK(middle(restored, 0) > 0.1 && middle(restored, 1) == 0.0); /* the red blocker */
    }
    rayes_image_free(open);
    rayes_image_free(shadow);
    rayes_image_free(none);
    rayes_image_free(old);
    rayes_image_free(restored);
}

/* The stainedglass blocker, unseen, with its Os 0.5: "primitive" shadows
 * by Os alone (grey, half the light), "shader" by the glass's colours. */
static void test_transmission_hit_mode(void)
{
    const char *glass =
        "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\n"
        "Attribute \"shade\" \"string transmissionhitmode\" [\"%s\"]\n"
        "Opacity [0.5 0.5 0.5]\nSurface \"stainedglass\"\n" BLOCKER "AttributeEnd\n";
    char prim[1024], shader[1024];
    snprintf(prim, sizeof prim, glass, "primitive");
    snprintf(shader, sizeof shader, glass, "shader");
    RayesImage *open = render_rib("", NULL), *p = render_rib(prim, NULL),
               *s = render_rib(shader, NULL);
    CHECK(open && p && s);
    if (open && p && s) {
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(middle(p, c) / middle(open, c), 0.5, 1e-4);
        double r = middle(s, 0) / middle(open, 0), b = middle(s, 2) / middle(open, 2);
        fprintf(stderr, "stained glass through \"shader\": %g %g of the light\n", r, b);
        CHECK(r > 0.5 && b > 0.5 && r < 1.0 && b < 1.0); /* Os times (1 - T) is below 0.5 */
        CHECK(fabs(r - b) > 1e-3);                       /* coloured */
    }
    rayes_image_free(open);
    rayes_image_free(p);
    rayes_image_free(s);
}

/* "opacitycache" 0: the blocker's opacity never reaches the cache. */
static void test_opacity_cache_attribute(void)
{
    const char *b = "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\n"
                    "Attribute \"shade\" \"int opacitycache\" [%d]\n"
                    "Opacity [0.5 0.5 0.5]\nSurface \"stainedglass\"\n" BLOCKER "AttributeEnd\n";
    for (int on = 0; on < 2; on++) {
        char text[1024];
        snprintf(text, sizeof text, b, on);
        RayesStats *st = NULL;
        RayesImage *img = render_rib(text, &st);
        uint64_t lookups = 0;
        static const char *const names[3] = {"cache/opacity/coarse/lookups",
                                             "cache/opacity/medium/lookups",
                                             "cache/opacity/fine/lookups"};
        for (int k = 0; k < 3; k++) {
            const RayesStat *v = rayes_stats_find(st, names[k]);
            lookups += v ? v->count : 0;
        }
        CHECK(img && (on ? lookups > 0 : lookups == 0));
        rayes_stats_free(st);
        rayes_image_free(img);
    }
}

/* The blocker's points, and Os 0 on its left edge and 1 on its right. */
#define GRADIENT_P "\"P\" [-0.5 -0.5 3  0.5 -0.5 3  0.5 0.5 3  -0.5 0.5 3]"
#define GRADIENT_OS "[0 0 0  1 1 1  1 1 1  0 0 0]"

/* Shadow rays see Os interpolated: the shadow of a polygon whose vertex
 * Os runs from 0 to 1 across it fades linearly (1 - Os of the light), by
 * any class that varies, and for a mesh and a subdivision mesh too. */
static void test_os_primvar_gradient_shadow(void)
{
    static const char *const blockers[] = {
        "Polygon " GRADIENT_P " \"vertex color Os\" " GRADIENT_OS "\n",
        "Polygon " GRADIENT_P " \"Os\" " GRADIENT_OS "\n", /* varying, predeclared */
        "PointsPolygons [4] [0 1 2 3] " GRADIENT_P " \"facevarying color Os\" " GRADIENT_OS "\n",
        "Patch \"bilinear\" \"P\" [-0.5 -0.5 3  0.5 -0.5 3  -0.5 0.5 3  0.5 0.5 3] "
        "\"vertex color Os\" [0 0 0  1 1 1  0 0 0  1 1 1]\n",
        "SubdivisionMesh \"bilinear\" [4] [0 1 2 3] [\"interpolateboundary\"] [0 0] [] "
        "[] " GRADIENT_P " \"varying color Os\" " GRADIENT_OS "\n",
    };
    RayesImage *open = render_rib("", NULL);
    for (size_t b = 0; b < sizeof blockers / sizeof blockers[0]; b++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\n%sAttributeEnd\n",
                 blockers[b]);
        RayesImage *img = render_cached(text, NULL, (int)(b % 2));
        CHECK(open && img);
        if (!open || !img) {
            rayes_image_free(img);
            continue;
        }
        /* Pixel column i looks along x = (i + 0.5 - SIZE / 2) / (SIZE / 2) *
         * tan 20 degrees, which meets the blocker at 3 times that; its one
         * sample is jittered within the pixel (half a pixel: 0.046). */
        double worst = 0, half_pixel = 3.0 * tan(20.0 * M_PI / 180.0) / SIZE;
        for (int i = 0; i < SIZE; i++) {
            double x = 3.0 * tan(20.0 * M_PI / 180.0) * (i + 0.5 - SIZE / 2) / (SIZE / 2);
            if (fabs(x) > 0.45)
                continue;
            int at = 4 * (SIZE / 2 * SIZE + i);
            double got = img->rgba[at] / open->rgba[at], want = 0.5 - x;
            worst = fmax(worst, fabs(got - want));
        }
        fprintf(stderr, "Os gradient %zu: transmission off 1 - Os by %g at most\n", b, worst);
        CHECK(worst < half_pixel + 0.005);
        rayes_image_free(img);
    }
    rayes_image_free(open);
}

/* Camera rays composite by the Os primitive variable (the hider), and the
 * opacity cache fills the stainedglass shader with it (put_point): cached
 * and uncached agree. */
static void test_os_primvar_camera_and_cache(void)
{
    const char *seen = "Surface \"constant\"\nColor [1 0 0]\nPolygon " GRADIENT_P
                       " \"vertex color Os\" " GRADIENT_OS "\n";
    RayesImage *img = render_rib(seen, NULL);
    CHECK(img != NULL);
    if (img) { /* red over the lit floor: green falls from the left edge to the right */
        const float *row = img->rgba + 4 * (SIZE / 2 * SIZE);
        CHECK(row[4 * (SIZE / 2 - 3) + 1] > row[4 * (SIZE / 2 + 2) + 1]);
        CHECK(row[4 * (SIZE / 2 - 3)] > 0.0f);
    }
    rayes_image_free(img);
    const char *glass = "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\n"
                        "Surface \"stainedglass\"\nPolygon " GRADIENT_P
                        " \"vertex color Os\" " GRADIENT_OS "\nAttributeEnd\n";
    RayesImage *cached = render_cached(glass, NULL, 1), *uncached = render_cached(glass, NULL, 0);
    CHECK(cached && uncached);
    if (cached && uncached) {
        double a = middle(cached, 0), b = middle(uncached, 0);
        fprintf(stderr, "stainedglass with an Os gradient: cached %g, uncached %g\n", a, b);
        CHECK(b > 0 && fabs(a / b - 1.0) < 0.03);
    }
    rayes_image_free(cached);
    rayes_image_free(uncached);
}

static RayesError parse(const char *text, const IoSink *sink, IoSettings *settings, char *err,
                        size_t err_size)
{
    IoReadOptions opt = {NULL, -1};
    io_settings_init(settings);
    return io_rib_parse("opacity.rib", (const unsigned char *)text, strlen(text), sink, &opt,
                        settings, err, err_size);
}

/* Option "limits" "opacitycachememory" in KB; bad values and names are
 * one-line errors at their line. */
static void test_option_and_errors(void)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings st;
    char err[512];
    CHECK(parse("Option \"limits\" \"opacitycachememory\" [2048]\n", &sink, &st, err, sizeof err) ==
          RAYES_OK);
    CHECK(st.opacity_cache_mb == 2048 * 1024 / 1e6);
    CHECK(parse("\nOption \"limits\" \"opacitycachememory\" [-1]\n", &sink, &st, err, sizeof err) !=
          RAYES_OK);
    CHECK(strstr(err, "opacity.rib:2:") && strstr(err, "opacitycachememory") && !strchr(err, '\n'));
    CHECK(parse("WorldBegin\nAttribute \"shade\" \"string transmissionhitmode\" [\"Os\"]\n", &sink,
                &st, err, sizeof err) != RAYES_OK);
    CHECK(strstr(err, "opacity.rib:2:") && strstr(err, "transmissionhitmode"));
    CHECK(parse("WorldBegin\n\nAttribute \"visibility\" \"string transmission\" \"glass\"\n", &sink,
                &st, err, sizeof err) != RAYES_OK);
    CHECK(strstr(err, "opacity.rib:3:") && strstr(err, "transparent"));
    rayes_scene_release(s);
}

/* The writer writes visibility and the opacity mode back, and reading
 * what it wrote renders the same. */
static void test_writer_round_trip(void)
{
    const char *in = "Projection \"perspective\" \"fov\" [40]\n"
                     "Option \"limits\" \"opacitycachememory\" [1000]\nWorldBegin\n"
                     "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0] "
                     "\"int diffuse\" [0]\nAttribute \"shade\" \"string transmissionhitmode\" "
                     "[\"primitive\"] \"int opacitycache\" [0]\n" BLOCKER "AttributeEnd\n"
                     "Polygon " GRADIENT_P " \"vertex color Os\" " GRADIENT_OS "\n"
                     "Sphere 1 -1 1 360\nWorldEnd\n";
    RibWriter *w = io_rib_writer_new();
    IoSink sink = io_rib_writer_sink(w);
    IoSettings st;
    char err[512], *buf = NULL;
    size_t size = 0;
    CHECK(parse(in, &sink, &st, err, sizeof err) == RAYES_OK);
    FILE *f = open_memstream(&buf, &size);
    CHECK(io_rib_writer_finish(w, &st, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    CHECK(strstr(buf, "Option \"limits\" \"int opacitycachememory\" [1000]") != NULL);
    CHECK(strstr(buf, "Attribute \"visibility\" \"int camera\" [0] \"int diffuse\" [0] "
                      "\"int specular\" [1] \"int transmission\" [1]") != NULL);
    CHECK(strstr(buf, "Attribute \"shade\" \"string transmissionhitmode\" [\"primitive\"] "
                      "\"int opacitycache\" [0]") != NULL);
    CHECK(strstr(buf, "\"vertex color Os\"") != NULL);
    /* and back to defaults for the sphere */
    CHECK(strstr(buf, "\"int camera\" [1] \"int diffuse\" [1]") != NULL);
    CHECK(strstr(buf, "[\"shader\"] \"int opacitycache\" [1]") != NULL);
    RibWriter *w2 = io_rib_writer_new();
    IoSink sink2 = io_rib_writer_sink(w2);
    char *buf2 = NULL;
    size_t size2 = 0;
    CHECK(parse(buf, &sink2, &st, err, sizeof err) == RAYES_OK);
    f = open_memstream(&buf2, &size2);
    CHECK(io_rib_writer_finish(w2, &st, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    CHECK(size == size2 && strcmp(buf, buf2) == 0); /* a fixed point */
    free(buf);
    free(buf2);
    io_rib_writer_free(w);
    io_rib_writer_free(w2);
}

TEST_MAIN(TEST(test_visibility), TEST(test_transmission_hit_mode),
          TEST(test_opacity_cache_attribute), TEST(test_option_and_errors),
          TEST(test_writer_round_trip), TEST(test_os_primvar_gradient_shadow),
          TEST(test_os_primvar_camera_and_cache))
