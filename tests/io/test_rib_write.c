/*
 * tests/io/test_rib_write.c — the RIB writer sink of io/rib_write.h: the
 * text each call writes (matrices transposed to RIB's row vectors, typed
 * inline parameters, the camera and settings before WorldBegin whatever
 * the order of the calls), floats that read back bit for bit, refused
 * input (non-finite numbers, bad meshes), and a built-in scene written
 * whole.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/builtin.h"
#include "io/rib_write.h"
#include "test.h"

#ifndef RAYES_TEST_DATA
#error "RAYES_TEST_DATA must name the shared data directory"
#endif

/* The RIB w writes, NUL-terminated (free it). */
static char *finish(RibWriter *w, const IoSettings *s)
{
    char *text = NULL, err[256];
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    CHECK(f != NULL);
    CHECK(io_rib_writer_finish(w, s, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    return text;
}

static int has(const char *text, const char *s)
{
    int ok = strstr(text, s) != NULL;
    if (!ok)
        fprintf(stderr, "  missing: %s\n", s);
    return ok;
}

/* Nonzero if a comes before b in text (both present). */
static int before(const char *text, const char *a, const char *b)
{
    const char *pa = strstr(text, a), *pb = strstr(text, b);
    return pa && pb && pa < pb;
}

static void test_calls(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink k = io_rib_writer_sink(w);
    const float m[16] = {1, 0, 0, 5, 0, 2, 0, 6, 0, 0, 3, 7, 0, 0, 0, 1};
    const float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const RayesParam sp[] = {{"Cs", RAYES_PARAM_COLOR, {0.5f, 0.25f, 1}, NULL},
                             {"Kd", RAYES_PARAM_FLOAT, {0.75f, 0, 0}, NULL},
                             {"texturename", RAYES_PARAM_STRING, {0}, "a \"b\".png"},
                             {"specularcolor", RAYES_PARAM_COLOR, {1, 2, 3}, NULL},
                             {"Os", RAYES_PARAM_COLOR, {0.5f, 0.5f, 0.5f}, NULL}};
    const float P4[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    float P16[16][3] = {{0}};
    const int nv[2] = {3, 4}, idx[7] = {0, 1, 2, 0, 1, 3, 2};
    const float q[5] = {2, 1, 0, 90, 360};
    const RayesParam lp[] = {{"from", RAYES_PARAM_COLOR, {1, 2, 3}, NULL},
                             {"intensity", RAYES_PARAM_FLOAT, {4, 0, 0}, NULL}};
    const float L[3] = {17, 12, 4};
    CHECK(k.set_search_path(w, "shader", "/a:&") == RAYES_OK);
    CHECK(k.set_shader(w, "paintedplastic", sp, 5) == RAYES_OK);
    CHECK(k.set_transform(w, m) == RAYES_OK);
    CHECK(k.set_displacement(w, "bumpy", sp + 1, 1) == RAYES_OK);
    CHECK(k.set_displacement_bound(w, 0.5f) == RAYES_OK);
    CHECK(k.set_shading_rate(w, 2) == RAYES_OK);
    CHECK(k.bilinear_patch(w, P4, NULL, 0) == RAYES_OK);
    CHECK(k.bicubic_patch(w, (const float(*)[3])P16, NULL, 0) == RAYES_OK);
    CHECK(k.bicubic_patch(w, (const float(*)[3])P16, NULL, 0) == RAYES_OK);
    CHECK(k.polygon_mesh(w, 2, nv, idx, 4, &P4[0][0], NULL, 0) == RAYES_OK);
    CHECK(k.sphere(w, 2) == RAYES_OK);
    CHECK(k.quadric(w, RAYES_QUADRIC_TORUS, q, 5, RAYES_QUADRIC_REVERSE) == RAYES_OK);
    CHECK(k.set_transform(w, id) == RAYES_OK);
    CHECK(k.set_displacement(w, NULL, NULL, 0) == RAYES_OK);
    CHECK(k.set_shader(w, "matte", NULL, 0) == RAYES_OK);
    CHECK(k.area_light(w, P4, L) == RAYES_OK);
    CHECK(k.light(w, "pointlight", lp, 2) == RAYES_OK);
    /* light links as Illuminate: light 1 (handle 2) off, the next light
     * off after its LightSource, then all on again; area lights untouched */
    const size_t only0 = 0;
    CHECK(k.light_count(w) == 2);
    CHECK(k.set_light_links(w, RAYES_LIGHT_LINKS_ONLY, &only0, 1) == RAYES_OK);
    CHECK(k.light(w, "ambientlight", NULL, 0) == RAYES_OK);
    CHECK(k.set_light_links(w, RAYES_LIGHT_LINKS_ALL, NULL, 0) == RAYES_OK);
    CHECK(k.light_count(w) == 3);
    /* the camera last: it still goes before WorldBegin */
    const float eye[3] = {0, 0, -10}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(k.set_camera(w, eye, at, up, 30) == RAYES_OK);
    IoSettings s;
    io_settings_init(&s);
    s.width = 320;
    s.height = 240;
    s.spp = 16;
    s.filter = RAYES_FILTER_GAUSSIAN;
    s.filter_width = 3;
    s.exposure_gain = 2;
    s.background[0] = 0.5f, s.background[3] = 1.0f;
    s.grid_size = 64;
    s.max_spp = 256;
    s.adaptive_error = 0.01f;
    s.n_displays = 2;
    snprintf(s.displays[0].name, sizeof s.displays[0].name, "out.exr");
    snprintf(s.displays[0].type, sizeof s.displays[0].type, "openexr");
    snprintf(s.displays[0].mode, sizeof s.displays[0].mode, "rgba");
    snprintf(s.displays[1].name, sizeof s.displays[1].name, "z.exr");
    snprintf(s.displays[1].type, sizeof s.displays[1].type, "openexr");
    snprintf(s.displays[1].mode, sizeof s.displays[1].mode, "z");
    char *t = finish(w, &s);
    CHECK(has(t, "##RenderMan RIB\n"));
    CHECK(has(t, "Format 320 240 1\n"));
    CHECK(has(t, "PixelSamples 4 4\n"));
    CHECK(has(t, "Hider \"raytrace\" \"int maxsamples\" [256]\n"));
    CHECK(has(t, "PixelVariance 0.00999999978\n"));
    CHECK(has(t, "PixelFilter \"gaussian\" 3 3\n"));
    CHECK(has(t, "Exposure 2 1\n"));
    CHECK(has(t, "Imager \"background\" \"color bgcolor\" [0.5 0 0]\n"));
    CHECK(has(t, "Option \"limits\" \"int gridsize\" [64]\n"));
    CHECK(has(t, "Display \"out.exr\" \"openexr\" \"rgba\"\n"));
    CHECK(has(t, "Display \"+z.exr\" \"openexr\" \"z\"\n"));
    CHECK(has(t, "Option \"searchpath\" \"string shader\" [\"/a:&\"]\n"));
    CHECK(has(t, "Projection \"perspective\" \"fov\" [30]\n"));
    /* eye (0 0 -10) looking down +z: camera x is world -x (a mirror) */
    CHECK(has(t, "Transform [-1 0 0 0 0 1 0 0 0 0 1 0 0 0 10 1]\n"));
    CHECK(before(t, "Projection", "WorldBegin") && before(t, "Transform [", "WorldBegin"));
    CHECK(before(t, "Display", "WorldBegin") && before(t, "Option", "WorldBegin"));
    CHECK(has(t, "Color [0.5 0.25 1]\nOpacity [0.5 0.5 0.5]\nSurface \"paintedplastic\" "
                 "\"float Kd\" [0.75] \"string texturename\" [\"a \\\"b\\\".png\"] "
                 "\"color specularcolor\" [1 2 3]\n"));
    CHECK(has(t, "TransformBegin\nConcatTransform [1 0 0 0 0 2 0 0 0 0 3 0 5 6 7 1]\n"));
    CHECK(has(t, "Displacement \"bumpy\" \"float Kd\" [0.75]\n"));
    CHECK(has(t, "Attribute \"displacementbound\" \"float sphere\" [0.5]"));
    CHECK(has(t, "ShadingRate 2\n"));
    CHECK(has(t, "Patch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n"));
    CHECK(has(t, "Basis \"bezier\" 3 \"bezier\" 3\nPatch \"bicubic\" \"P\" [0 0"));
    CHECK(strstr(strstr(t, "Basis") + 1, "Basis") == NULL); /* once */
    CHECK(has(t, "PointsPolygons [3 4]\n  [0 1 2 0 1 3 2]\n  \"P\" [0 0 0 1 0 0 0 1 0\n   1 1 0]\n"));
    CHECK(has(t, "Sphere 2 -2 2 360\n"));
    CHECK(has(t, "AttributeBegin\nReverseOrientation\nTorus 2 1 0 90 360\nAttributeEnd\n"));
    CHECK(has(t, "TransformEnd\nDisplacement \"null\"\nColor [1 1 1]\nOpacity [1 1 1]\n"
                 "Surface \"matte\"\n"));
    CHECK(has(t, "AttributeBegin\nAreaLightSource \"arealight\" 1 \"color lightcolor\" [17 12 4]\n"
                 "Polygon \"P\" [0 0 0 1 0 0 0 1 0 1 1 0]\nAttributeEnd\n"));
    /* RenderMan's units: 4 / pi; shadows said, since RenderMan's cast none */
    CHECK(has(t, "LightSource \"pointlight\" 2 \"point from\" [1 2 3] \"float intensity\" "
                 "[1.2732395447351628] \"float shadows\" [1]\n"));
    CHECK(has(t, "[1.2732395447351628] \"float shadows\" [1]\nIlluminate 2 0\nLightSource "
                 "\"ambientlight\" 3\nIlluminate 3 0\n"
                 "Illuminate 2 1\nIlluminate 3 1\n"));
    CHECK(!has(t, "Illuminate 1"));
    CHECK(has(t, "WorldEnd\n"));
    free(t);
    io_rib_writer_free(w);
}

/* %.9g reads back bit for bit; a portrait image gets RenderMan's fov of
 * the shorter (horizontal) side. */
static void test_round_trip(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink k = io_rib_writer_sink(w);
    const float v[4][3] = {{0.1f, 1.0f / 3.0f, 1e-30f},
                           {16777217.0f, -2.5e-7f, 3.14159265f},
                           {1e30f, -0.0f, 7.0f / 9.0f},
                           {123456.789f, 0.3f, 2.0f / 3.0f}};
    CHECK(k.bilinear_patch(w, v, NULL, 0) == RAYES_OK);
    const float eye[3] = {1, 2, 3}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(k.set_camera(w, eye, at, up, 40) == RAYES_OK);
    IoSettings s;
    io_settings_init(&s);
    s.width = 100;
    s.height = 200;
    char *t = finish(w, &s);
    const char *p = strstr(t, "Patch \"bilinear\" \"P\" [");
    CHECK(p != NULL);
    int exact = p != NULL;
    if (p) {
        p += strlen("Patch \"bilinear\" \"P\" [");
        for (int i = 0; i < 12; i++) {
            char *end;
            float f = strtof(p, &end);
            exact &= f == v[i / 3][i % 3] && end != p; /* exact; -0 is written 0 */
            p = end;
        }
    }
    CHECK(exact);
    const char *fov = strstr(t, "\"fov\" [");
    CHECK(fov != NULL);
    if (fov) {
        double want = atan(tan(20.0 * M_PI / 180.0) * 0.5) * 360.0 / M_PI;
        CHECK_NEAR(strtod(fov + 7, NULL), want, 1e-5);
    }
    free(t);
    io_rib_writer_free(w);
}

static void test_refused(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink k = io_rib_writer_sink(w);
    const float nan4[4][3] = {{NAN, 0, 0}};
    const int nv[1] = {5}, idx[5] = {0, 0, 0, 0, 0}, bad[3] = {0, 1, 7};
    const int three[1] = {3};
    const float P[9] = {0};
    const float q[3] = {1, 2, 3};
    CHECK(k.bilinear_patch(w, nan4, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(k.get_error(w), "non-finite") != NULL);
    CHECK(k.polygon_mesh(w, 1, nv, idx, 3, P, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(k.polygon_mesh(w, 1, three, bad, 3, P, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(k.quadric(w, RAYES_QUADRIC_SPHERE, q, 3, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(k.set_shading_rate(w, -1) == RAYES_ERROR_INVALID_ARGUMENT);
    /* refused as the scene refuses it, so both sinks accept the same calls */
    const float quad[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, negative[3] = {1, -1, 1};
    CHECK(k.area_light(w, quad, negative) == RAYES_ERROR_INVALID_ARGUMENT);
    char *t = finish(w, NULL);
    CHECK(strstr(t, "Patch") == NULL && strstr(t, "PointsPolygons") == NULL);
    CHECK(strstr(t, "AreaLightSource") == NULL);
    free(t);
    io_rib_writer_free(w);
}

/* The benchmark scene, written whole: 64 bicubic patches (two teapots),
 * five walls (four planar polygons, and the red wall, which is not planar,
 * a bilinear patch), a light, the camera. */
static void test_builtin(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink k = io_rib_writer_sink(w);
    char err[512];
    CHECK(io_builtin_scene("cornell-teapots", RAYES_TEST_DATA, &k, err, sizeof err) == RAYES_OK);
    char *t = finish(w, NULL);
    int patches = 0, meshes = 0, bilinear = 0;
    for (const char *p = t; (p = strstr(p, "Patch \"bicubic\"")); p++)
        patches++;
    for (const char *p = t; (p = strstr(p, "PointsPolygons")); p++)
        meshes++;
    for (const char *p = t; (p = strstr(p, "Patch \"bilinear\"")); p++)
        bilinear++;
    CHECK(patches == 64);
    CHECK(meshes == 4 && bilinear == 1);
    CHECK(has(t, "AreaLightSource") && has(t, "Surface \"mirror\""));
    CHECK(has(t, "Projection \"perspective\" \"fov\" [39.3077011]"));
    free(t);
    io_rib_writer_free(w);
}

/* Patterns are written as RenderMan's Pattern request, and a parameter
 * bound to one as "reference pattern NAME", which the RIB reader reads. */
static void test_patterns(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink k = io_rib_writer_sink(w);
    const RayesParam pp[] = {{"tex1", RAYES_PARAM_COLOR, {1, 0, 0}, NULL},
                             {"uscale", RAYES_PARAM_FLOAT, {8, 0, 0}, NULL},
                             {"tex2", RAYES_PARAM_PATTERN, {0}, "0:img"}};
    const RayesParam sp[] = {{"roughness", RAYES_PARAM_PATTERN, {0}, "1:checks"}};
    CHECK(k.pattern(w, "1:checks", "checkerboard", pp, 3) == RAYES_OK);
    CHECK(k.set_shader(w, "conductor", sp, 1) == RAYES_OK);
    CHECK(k.set_displacement(w, "displace", sp, 1) == RAYES_OK);
    IoSettings s;
    io_settings_init(&s);
    char *t = finish(w, &s);
    CHECK(has(t,
              "Pattern \"checkerboard\" \"1:checks\" \"color tex1\" [1 0 0] \"float uscale\" [8] "
              "\"reference pattern tex2\" [\"0:img\"]"));
    CHECK(has(t, "Surface \"conductor\" \"reference pattern roughness\" [\"1:checks\"]"));
    CHECK(has(t, "Displacement \"displace\" \"reference pattern roughness\" [\"1:checks\"]"));
    CHECK(before(t, "Pattern", "Surface"));
    free(t);
    io_rib_writer_free(w);
    /* an array (densitygrid's density) as a float array */
    w = io_rib_writer_new();
    k = io_rib_writer_sink(w);
    const float d[3] = {0.5f, 1.5f, 2};
    RayesParam gp[2] = {{"nx", RAYES_PARAM_FLOAT, {3, 0, 0}, NULL}};
    gp[1] = (RayesParam){"density", RAYES_PARAM_FLOATS, {0}, NULL, d, 3};
    CHECK(k.pattern(w, "g", "densitygrid", gp, 2) == RAYES_OK);
    t = finish(w, &s);
    CHECK(has(t, "Pattern \"densitygrid\" \"g\" \"float nx\" [3] \"float density\" [0.5 1.5 2]"));
    free(t);
    io_rib_writer_free(w);
}

TEST_MAIN(TEST(test_calls), TEST(test_round_trip), TEST(test_refused), TEST(test_builtin),
          TEST(test_patterns))
